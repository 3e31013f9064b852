// The five 2D jump tasks under the "jump2d" controller, as their files named it before they
// named skill files (skills/): for the tests of jump2d's own keys, which vary them.
//
//   const fs::path file = test_files::jump2d_variant("jump_high", "paper_aim",
//       {"landing_at_touchdown =", "landing_reach ="}, {{"controller", "level_feet = true"}});
//
// Like task_variant(), with the [controller] table first replaced by jump2d's: the keys
// below (but those `drop_lines_starting` names), then the lines added to it.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "task_variant.h"

namespace diverse::test_files {

inline const std::map<std::string, std::vector<std::string>>& jump2d_keys() {
  static const std::map<std::string, std::vector<std::string>> keys = {
      {"backflip",
       {"landing_control = true", "tuck_time = 0.08", "open_time = 0.1", "open_turn = 5.1", "balance_kp = 4000.0", "balance_kd = 800.0", "balance_max_force = 800.0"}},
      {"jump_forward",
       {"landing_control = true", "stance_landing = true", "stand_after = 0.0", "landing_at_touchdown = true", "landing_reach = 0.05", "balance_kp = 4000.0", "balance_kd = 800.0", "balance_max_force = 800.0", "crouch_lean = 0.2"}},
      {"jump_high",
       {"landing_control = true", "level_feet = true", "landing_at_touchdown = true", "landing_reach = 0.05", "balance_kp = 4000.0", "balance_kd = 800.0", "balance_max_force = 800.0"}},
      {"jump_onto",
       {"landing_control = true", "landing_height = 0.5", "balance_kp = 4000.0", "balance_kd = 800.0", "balance_max_force = 800.0"}},
      {"jump_over",
       {"landing_control = true", "stance_landing = true", "stand_after = 0.0", "landing_at_touchdown = true", "landing_reach = 0.05", "balance_kp = 4000.0", "balance_kd = 800.0", "balance_max_force = 800.0", "crouch_lean = 0.2"}},
  };
  return keys;
}

inline std::filesystem::path jump2d_variant(const std::string& task, const std::string& name,
                                            std::vector<std::string> drop_lines_starting,
                                            std::vector<std::pair<std::string, std::string>> add_to_sections) {
  std::string table = "type = \"jump2d\"";
  for (const std::string& line : jump2d_keys().at(task)) {
    bool dropped = false;
    for (const std::string& key : drop_lines_starting) dropped = dropped || line.rfind(key, 0) == 0;
    if (!dropped) table += "\n" + line;
  }
  bool added = false;
  for (auto& [section, lines] : add_to_sections) {
    if (section == "controller") {
      lines = table + "\n" + lines;
      added = true;
    }
  }
  if (!added) add_to_sections.emplace_back("controller", table);
  // The skill file and the module settings it overrode go.
  for (const char* key : {"skill =", "landing_height =", "balance ="}) drop_lines_starting.emplace_back(key);
  return task_variant(task, name, drop_lines_starting, add_to_sections);
}

}  // namespace diverse::test_files
