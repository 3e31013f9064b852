// Reading and writing whole text files in tests (models and character files edited on the fly).
#pragma once

#include <fstream>
#include <sstream>
#include <string>

namespace diverse::test_files {

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

}  // namespace diverse::test_files
