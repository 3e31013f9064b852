// Forward pitch (kind "pitch"): the root's forward pitch from standing (rad, about the
// world's lateral axis; for a free root, its standing forward axis's elevation) stays at
// most `max` throughout the motion (the bird robot's long jump).
//
//   max = 0.7     # rad
//
// C adds K_c d^2, d the excess (rad). The largest pitch only grows: once over, the motion
// cannot meet it.
#pragma once

#include "task/term.h"

namespace diverse {

class PitchConstraint : public Constraint {
 public:
  using Constraint::Constraint;
  const char* kind() const override { return "pitch"; }
  void penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const override;
  double margin(const Task& task, const MotionSummary& motion) const override;
  bool broken(const Task& task, const MotionSummary& so_far, Moment moment) const override;

  double max = 0;        // rad
  double weight = 5000;  // K_c
};

void read_pitch(const TomlReader& r, const Task& task, TaskConstraints& c);

}  // namespace diverse
