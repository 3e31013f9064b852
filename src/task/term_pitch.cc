#include "task/term_pitch.h"

#include <algorithm>

#include "core/toml_reader.h"
#include "task/constraints.h"
#include "task/task.h"

namespace diverse {

void read_pitch(const TomlReader& r, const Task& task, TaskConstraints& c) {
  (void)task;
  r.only({"max", "weight"});
  auto t = std::make_shared<PitchConstraint>(r.path());
  t->max = r.number("max", 0.01, 3.14);
  t->weight = term_weight(r, c);
  c.terms.push_back(std::move(t));
}

void PitchConstraint::penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const {
  (void)task;
  const double d = std::max(0.0, motion.max_forward_pitch - max);
  report.add("pitch", d, weight * d * d);
}

double PitchConstraint::margin(const Task& task, const MotionSummary& motion) const {
  (void)task;
  return 0.2 * (max - motion.max_forward_pitch);
}

bool PitchConstraint::broken(const Task& task, const MotionSummary& so_far, Moment moment) const {
  (void)task;
  return moment == Moment::kStep && so_far.max_forward_pitch > max;
}

}  // namespace diverse
