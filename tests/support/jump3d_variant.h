// The two 3D jump tasks under the "jump3d" controller, as their files named it before they
// named skill files (skills/jump3d.toml, skills/robot_jump.toml): for the tests of jump3d's
// own keys.
//
//   const Task t = load_task(test_files::jump3d_variant("robot_jump").string());
#pragma once

#include <map>
#include <string>

#include "task_variant.h"

namespace diverse::test_files {

inline const std::map<std::string, std::string>& jump3d_keys() {
  static const std::map<std::string, std::string> keys = {
      {"jump_backwards", "landing_control = true\nasymmetric = true"},
      {"robot_jump", "landing_control = true\nasymmetric = true\njoint_space_extend = true\nextend_root_kd = 400.0"},
  };
  return keys;
}

inline std::filesystem::path jump3d_variant(const std::string& task, const std::string& extra = "") {
  return task_variant(task, "jump3d_" + task + "_" + std::to_string(std::hash<std::string>{}(extra)), {"skill ="},
                      {{"controller", "type = \"jump3d\"\n" + jump3d_keys().at(task) + (extra.empty() ? "" : "\n" + extra)}});
}

}  // namespace diverse::test_files
