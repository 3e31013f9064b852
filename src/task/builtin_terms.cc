// The constraint kinds this build knows, by the name a task file's [[constraints]] kind
// gives (task/term.h). A new kind adds its line here and lives in its own file.
#include <string>
#include <vector>

#include "core/error.h"
#include "core/toml_reader.h"
#include "task/task.h"
#include "task/term.h"
#include "task/term_clearance.h"
#include "task/term_fall.h"
#include "task/term_foot_slip.h"
#include "task/term_landing.h"
#include "task/term_min_length.h"
#include "task/term_on_box.h"
#include "task/term_peak_height.h"
#include "task/term_pitch.h"
#include "task/term_rotation.h"

namespace diverse {

void read_half_timestep(const TomlReader& r, const Task& task, TaskConstraints& c);  // term_half_timestep.cc

std::vector<ConstraintKind> builtin_constraint_kinds() {
  // name, description, walks, repeats, reader
  return {
      {"landing", "the feet land in a box along x or a disc", false, false, read_landing},
      {"on_box", "the feet land on a box object, away from its edges", false, false, read_on_box},
      {"clearance", "every body stays clear of an obstacle object", false, false, read_clearance},
      {"min_length", "the feet land beyond a distance", false, false, read_min_length},
      {"peak_height", "the centre of mass rises high enough in flight", false, false, read_peak_height},
      {"rotation", "the root turns about pitch, roll or the vertical", false, true, read_rotation},
      {"pitch", "the root leans forward no more than a bound", false, false, read_pitch},
      {"foot_slip", "a planted foot slides no more than a bound per stance", true, false, read_foot_slip},
      {"fall", "the fall penalty and the bodies that may touch the ground", true, false, read_fall},
      {"half_timestep", "the motion meets the task at half the timestep too", true, false, read_half_timestep},
  };
}

const ConstraintKind& find_constraint_kind(const std::string& name, const std::string& where) {
  static const std::vector<ConstraintKind> kinds = builtin_constraint_kinds();
  for (const ConstraintKind& kind : kinds) {
    if (name == kind.name) return kind;
  }
  std::string known;
  for (const ConstraintKind& kind : kinds) known += std::string(known.empty() ? "\"" : ", \"") + kind.name + "\"";
  throw UserError(where + ": expected one of " + known + ", got \"" + name + "\"");
}

double term_weight(const TomlReader& r, const TaskConstraints& c) {
  return r.number("weight", 1e-6, 1e9, c.weight);
}

}  // namespace diverse
