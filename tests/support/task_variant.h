// A committed task file edited for a test: the lines of some keys removed, lines added at
// the top of sections, its relative paths made absolute, written to a scratch directory
// of this process (temp/diverse_task_variants_<pid>/<name>.toml).
//
//   const fs::path file = test_files::task_variant("jump_high", "paper_aim",
//       {"landing_at_touchdown =", "landing_reach ="}, {{"controller", "level_feet = true"}});
#pragma once

#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "text_files.h"

namespace diverse::test_files {

inline std::filesystem::path task_variant(const std::string& task, const std::string& name,
                                          const std::vector<std::string>& drop_lines_starting,
                                          const std::vector<std::pair<std::string, std::string>>& add_to_sections) {
  const std::string source = DIVERSE_SOURCE_DIR;
  std::string text = read_text(source + "/tasks/" + task + ".toml");
  for (const std::string& key : drop_lines_starting) {
    for (auto at = text.find("\n" + key); at != std::string::npos; at = text.find("\n" + key))
      text.erase(at + 1, text.find('\n', at + 1) - at);
  }
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    if (at == std::string::npos) throw std::runtime_error(task + ".toml has no " + from);
    text.replace(at, from.size(), to);
  };
  replace("character = \"../", "character = \"" + source + "/");
  if (text.find("skill = \"../") != std::string::npos) replace("skill = \"../", "skill = \"" + source + "/");
  replace("m0 = \"", "m0 = \"" + source + "/tasks/");
  if (text.find("\nbase = \"") != std::string::npos) replace("\nbase = \"", "\nbase = \"" + source + "/tasks/");
  for (const auto& [section, lines] : add_to_sections) {
    const std::string header = "\n[" + section + "]\n";
    if (text.find(header) == std::string::npos) text += header;
    replace(header, header + lines + "\n");
  }
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("diverse_task_variants_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / (name + ".toml");
  write_text(file.string(), text);
  return file;
}

}  // namespace diverse::test_files
