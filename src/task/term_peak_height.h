// Peak height (kind "peak_height"): the whole-body COM rises during flight to at least
// `min` m above the floor, or `above_standing` m above its height in the start pose (so
// that a body with longer legs has to rise as far as any other).
//
//   above_standing = 0.293     # or: min = 1.4
//
// C adds K_c d^2, d the shortfall (m). Once the peak is behind, the shortfall is known.
#pragma once

#include "task/term.h"

namespace diverse {

class PeakHeightConstraint : public Constraint {
 public:
  using Constraint::Constraint;
  const char* kind() const override { return "peak_height"; }
  void penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const override;
  double margin(const Task& task, const MotionSummary& motion) const override;
  bool broken(const Task& task, const MotionSummary& so_far, Moment moment) const override;

  // The peak COM height it asks for (m above the floor).
  double required(const MotionSummary& motion) const;

  double min = 0;          // m
  bool relative = false;   // `min` is above the standing COM (above_standing)
  double weight = 5000;    // K_c
};

void read_peak_height(const TomlReader& r, const Task& task, TaskConstraints& c);

}  // namespace diverse
