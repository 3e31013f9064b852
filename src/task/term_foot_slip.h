// Foot slip (kind "foot_slip", jumps and walks): a planted foot slides at most
// `per_stance` m in any one stance, measured in the rollout step by step as
// task/foot_slip.h measures a replay (docs/reference/foot-slip.md): the largest stance's
// slide of either side, every stance of the motion counted.
//
//   per_stance = 0.02     # m
//
// C adds K_c d^2, d the excess (m) of the worst stance. Its margin is 0.1 m times the
// share of the bound left unused (a stance that slides half the bound counts as 5 cm of
// slack, as a landing 5 cm inside its box does).
#pragma once

#include "task/term.h"

namespace diverse {

class FootSlipConstraint : public Constraint {
 public:
  using Constraint::Constraint;
  const char* kind() const override { return "foot_slip"; }
  void penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const override;
  double margin(const Task& task, const MotionSummary& motion) const override;
  // MotionSummary::foot_slip, from a FootSlipMeter after every step.
  std::unique_ptr<TermObserver> observer(const mjModel* m, const Character& body) const override;

  // How far (m) the motion's worst stance slid beyond the bound (0 within it).
  double excess(const MotionSummary& motion) const;

  double per_stance = 0.02;  // m
  double weight = 5000;      // K_c
};

void read_foot_slip(const TomlReader& r, const Task& task, TaskConstraints& c);

}  // namespace diverse
