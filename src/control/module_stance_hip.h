// "stance_hip": the root held by the stance hip (SIMBICON, Yin, Loken, van de Panne 2007,
// section 3.1: tau_stance = -tau_torso - tau_swing; as in Coros, Beaudoin, van de Panne
// 2010's Cartwheel-3D). The root is unactuated; it tracks the phase's root target (pitch
// and roll in the heading frame, control/heading_frame.h) with the world torque
// T = root_kp e_root - root_kd w_root, and the stance hip supplies T together with what the
// other hinges on the root (swing hip, waist) take away: on each stance-hip hinge,
// tau = -a . (T + sum_o tau_o a_o). A universal hip cannot turn the root about its missing
// axis, so the yaw part is lost.
//
// In double support (the swing foot still down, early in a step) both hips share that
// torque equally and the swing femur is not tracked. The root comes first: if the stance
// hip cannot take the swing hip's reaction on top of the root's torque, the swing hip's
// torque is scaled down by the largest factor that keeps every stance-hip hinge within its
// limit (the damping estimated at the current joint rate). The root's damping
// -root_kd w_root is split by a . w_root = a . w_thigh - qdot: its -qdot part is the hip's
// own damping, implicit in the drive.
//
// Settings: root_kp (Nm/rad; 0, the default: 2 M g h, M the mass and h the standing COM
// height), root_kd (Nm s/rad; 0: root_kp / 5 s). Runs last among a phase's modules (it
// reads every other joint's torque). Phases with a swing leg and a root target.
#pragma once

#include "control/heading_frame.h"
#include "control/skill_module.h"

namespace diverse {

class StanceHipModule : public SkillModule {
 public:
  StanceHipModule(const ModuleSettings& settings, const Character& body);
  void reset(const mjModel* m, const mjData* d, SkillState& s) override;
  void adjust_torques(const mjModel* m, const mjData* d, SkillState& s) override;

 private:
  double root_kp_, root_kd_;
  LegLayout layout_;
};

}  // namespace diverse
