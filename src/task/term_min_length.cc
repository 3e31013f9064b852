#include "task/term_min_length.h"

#include <algorithm>
#include <cmath>

#include "core/toml_reader.h"
#include "task/constraints.h"
#include "task/task.h"

namespace diverse {

void read_min_length(const TomlReader& r, const Task& task, TaskConstraints& c) {
  (void)task;
  r.only({"length", "weight"});
  auto t = std::make_shared<MinLengthConstraint>(r.path());
  t->length = r.number("length", -20, 20);
  t->weight = term_weight(r, c);
  c.terms.push_back(std::move(t));
}

void MinLengthConstraint::penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const {
  (void)task;
  const double d = std::max(std::max(0.0, length - motion.touchdown_feet_x), std::max(0.0, length - motion.feet_x));
  report.add("min_length", d, weight * d * d);
}

double MinLengthConstraint::margin(const Task& task, const MotionSummary& motion) const {
  (void)task;
  return std::min(motion.touchdown_feet_x - length, motion.feet_x - length);
}

std::optional<std::pair<double, double>> MinLengthConstraint::feet_x_range(const Task& task) const {
  (void)task;
  return std::make_pair(length, static_cast<double>(INFINITY));
}

}  // namespace diverse
