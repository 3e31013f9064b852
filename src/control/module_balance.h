// "balance": Jacobian-transpose balance (Pratt, Chew, Torres, Dilworth, Pratt 2001, virtual
// model control; the paper's section 6 balance in start, crouch and land). A virtual force
// F on the centre of mass: F_x = kp (x_ref - x) + kd (v_ref - v) servos the COM over the
// middle of the feet plus `offset`, clamped to +-max_force; F_z = gravity_compensation M g
// carries the weight. It becomes joint torques tau = J^T F of the ankles, knees and hips,
// each leg carrying half: J is the Jacobian of the COM, taken as a point fixed to the
// upper body, with the feet as the base, so tau_j = -(c - p_j) x F (the 2D cross product,
// c the COM, p_j the joint's position). Only while the character touches something.
//
// `lean` (m, > 0): the reference moves from over the feet to `lean` ahead of them over the
// phase, at the speed that takes (v_ref), so a crouch that leans in to build a jump's
// forward speed follows the same path after a push instead of falling from where the push
// left it.
//
// Settings: kp (N/m), kd (N s/m), max_force (N), gravity_compensation (default 1),
// offset (m, default 0), lean (m, default 0). Planar characters.
#pragma once

#include "control/skill_module.h"

namespace diverse {

class BalanceModule : public SkillModule {
 public:
  BalanceModule(const ModuleSettings& settings, const Character& body);
  void add_torques(const mjModel* m, const mjData* d, SkillState& s) override;

 private:
  double kp_, kd_, max_force_, gravity_compensation_, offset_, lean_;
  std::vector<int> legs_;  // ankle, knee and hip joints
};

}  // namespace diverse
