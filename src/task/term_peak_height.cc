#include "task/term_peak_height.h"

#include <algorithm>

#include "core/toml_reader.h"
#include "task/constraints.h"
#include "task/task.h"

namespace diverse {

void read_peak_height(const TomlReader& r, const Task& task, TaskConstraints& c) {
  (void)task;
  r.only({"min", "above_standing", "weight"});
  auto t = std::make_shared<PeakHeightConstraint>(r.path());
  if (r.has("above_standing")) {
    if (r.has("min")) r.fail("min", "expected either min (m above the floor) or above_standing (m above the standing COM), not both");
    t->relative = true;
    t->min = r.number("above_standing", 0, 5);
  } else {
    t->min = r.number("min", 0, 5);
  }
  t->weight = term_weight(r, c);
  c.terms.push_back(std::move(t));
}

double PeakHeightConstraint::required(const MotionSummary& motion) const {
  return min + (relative ? motion.standing_com_z : 0.0);
}

void PeakHeightConstraint::penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const {
  (void)task;
  const double d = std::max(0.0, required(motion) - motion.peak_com_z);
  report.add("peak_height", d, weight * d * d);
}

double PeakHeightConstraint::margin(const Task& task, const MotionSummary& motion) const {
  (void)task;
  return motion.peak_com_z - required(motion);
}

bool PeakHeightConstraint::broken(const Task& task, const MotionSummary& so_far, Moment moment) const {
  (void)task;
  const double d = std::max(0.0, required(so_far) - so_far.peak_com_z);
  return moment == Moment::kPastPeak && weight * d * d > 0;
}

}  // namespace diverse
