// A skill file edited for a test: each `from` text replaced by its `to` (every one must be
// in the file), written to a scratch directory of this process
// (temp/diverse_skill_variants_<pid>/<name>.toml). Its path goes into a task variant's
// [controller] table (support/task_variant.h) in place of the task's own skill:
//
//   const fs::path skill = test_files::skill_variant("skills/backflip.toml", "clocked",
//       {{"on = [\"peak\", \"spotted\"]", "on = [\"peak\", \"turned\"], angle = 3.3"}});
//   const fs::path task = test_files::task_variant("backflip", "clocked", {"skill ="},
//       {{"controller", test_files::skill_line(skill)}});
#pragma once

#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "text_files.h"

namespace diverse::test_files {

// `skill`: a path relative to the source directory.
inline std::filesystem::path skill_variant(const std::string& skill, const std::string& name,
                                           const std::vector<std::pair<std::string, std::string>>& replace) {
  std::string text = read_text(std::string(DIVERSE_SOURCE_DIR) + "/" + skill);
  for (const auto& [from, to] : replace) {
    const auto at = text.find(from);
    if (at == std::string::npos) throw std::runtime_error(skill + " has no " + from);
    text.replace(at, from.size(), to);
  }
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("diverse_skill_variants_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / (name + ".toml");
  write_text(file.string(), text);
  return file;
}

// The [controller] line that names `skill`, an absolute path or one relative to the source
// directory.
inline std::string skill_line(const std::filesystem::path& skill) {
  const std::filesystem::path path = skill.is_absolute() ? skill : std::filesystem::path(DIVERSE_SOURCE_DIR) / skill;
  return "skill = \"" + path.string() + "\"";
}

}  // namespace diverse::test_files
