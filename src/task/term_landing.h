// The landing constraint (kind "landing"): where the feet come down and stay.
//
//   center = 1.0, half_width = 0.15      # a box along x: feet x within center +- half_width (m)
//   center = 0.0, radius = 0.25, lateral = 0.0   # or a disc of `radius` around (center, lateral)
//
// The feet (the mean of the two foot centres) are judged at the first touch-down after
// flight and at rest, the larger violation counting: a motion that touches down short
// and hops or slides the rest of the way does not land in the box. C adds K_c d^2, d the
// distance (m) outside the box or disc.
#pragma once

#include "task/term.h"

namespace diverse {

class LandingConstraint : public Constraint {
 public:
  using Constraint::Constraint;
  const char* kind() const override { return "landing"; }
  void penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const override;
  double margin(const Task& task, const MotionSummary& motion) const override;
  std::optional<std::pair<double, double>> feet_x_range(const Task& task) const override;

  double center = 0, half_width = 0.15;  // m, along x
  double lateral = 0;                    // m, y of a disc's centre
  double radius = 0;                     // m; > 0: a disc instead of a box (3D characters)
  double weight = 5000;                  // K_c
};

void read_landing(const TomlReader& r, const Task& task, TaskConstraints& c);

}  // namespace diverse
