// Scratch directories for tests that write files. The name carries the process id, so
// two test processes running at once (ctest -j, or two checkouts tested side by side)
// never write into, or delete, each other's files.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace diverse::test_files {

// temp/diverse_<name>_<pid>, emptied (not created).
inline std::filesystem::path scratch_dir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("diverse_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

}  // namespace diverse::test_files
