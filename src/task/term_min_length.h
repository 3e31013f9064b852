// Minimum jump length (kind "min_length"): the feet end at x >= `length` (m), at the
// first touch-down and at rest. C adds K_c d^2, d the shortfall (m).
//
//   length = 1.2
#pragma once

#include "task/term.h"

namespace diverse {

class MinLengthConstraint : public Constraint {
 public:
  using Constraint::Constraint;
  const char* kind() const override { return "min_length"; }
  void penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const override;
  double margin(const Task& task, const MotionSummary& motion) const override;
  std::optional<std::pair<double, double>> feet_x_range(const Task& task) const override;

  double length = 0;     // m
  double weight = 5000;  // K_c
};

void read_min_length(const TomlReader& r, const Task& task, TaskConstraints& c);

}  // namespace diverse
