// The half-timestep check (kind "half_timestep", no keys; table form: half_timestep =
// true): every motion that meets the task is simulated again with the timestep halved
// and meets it only if it still does there, its feet landing within kTimestepAgreement
// of the same spot (task/constraints.h, half_timestep_term(); TaskEvaluator runs it).
#include <string>

#include "core/toml_reader.h"
#include "task/task.h"
#include "task/term.h"

namespace diverse {

void read_half_timestep(const TomlReader& r, const Task& task, TaskConstraints& c) {
  (void)task;
  for (const auto& [key, value] : r.raw()) {
    (void)value;
    r.fail(std::string(key.str()), "expected no key: the half-timestep check has no settings");
  }
  c.half_timestep = true;
}

}  // namespace diverse
