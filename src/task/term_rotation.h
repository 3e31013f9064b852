// Rotation (kind "rotation"): the root turns `turns` full turns +- `tolerance` rad about
// one axis.
//
//   axis = "pitch", turns = 1, tolerance = 0.5, penalty = 100000, min_flight = 5.0
//   axis = "vertical", turns = 0.5, tolerance = 0.3, penalty = 100000
//
// axis = "pitch" (the default; the only axis of a planar character): about the world's
// lateral axis, positive backwards (a backflip turns +1). Measured from standing to
// standing (the root's pitch at rest minus in the start pose); `min_flight` (rad, in the
// direction of the turns) asks the root to turn at least that much between take-off and
// the first touch-down as well: a flip turns in the air, not on its feet.
//
// axis = "roll" (about the world's forward axis x, positive turning the left side up: a
// cartwheel or side flip to the right) and axis = "vertical" (about the world's vertical,
// positive turning left seen from above: a jump that lands facing back turns 0.5), for a
// free-root character only: measured where a person judges a turn, as the root's total
// turn about that axis between take-off and the first touch-down (the world angular
// velocity about the axis, integrated step by step, so several turns count as several).
//
// C adds `penalty` + K_c d^2 when the turn misses by d > 0 beyond the tolerance (rad), and
// for min_flight K_c d^2 for a shortfall of d rad. A motion that never landed has no turn
// in the air; the fall term covers it. A task lists at most one rotation per axis.
#pragma once

#include "task/term.h"

namespace diverse {

enum class RotationAxis { kPitch, kRoll, kVertical };

class RotationConstraint : public Constraint {
 public:
  using Constraint::Constraint;
  const char* kind() const override { return "rotation"; }
  void penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const override;
  double margin(const Task& task, const MotionSummary& motion) const override;
  // Pitch: the rotation from standing to standing, known only at rest, as asked.
  void assume_met_at_rest(MotionSummary& s) const override;

  // The measured turn it judges (rad): pitch from standing to standing, or the flight
  // turn about roll or vertical.
  double turned(const MotionSummary& motion) const;

  RotationAxis axis = RotationAxis::kPitch;
  double turns = 1;               // full turns about the axis, signed as above
  double tolerance = 0.5;         // rad
  double penalty = 100000;        // constant added when missed
  double min_flight = 0;          // rad, pitch only; 0 = none
  double weight = 5000;           // K_c
};

void read_rotation(const TomlReader& r, const Task& task, TaskConstraints& c);

// The task's rotation constraint about `axis`, or nullptr.
const RotationConstraint* find_rotation(const TaskConstraints& c, RotationAxis axis);

}  // namespace diverse
