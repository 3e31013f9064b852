// "root_damping": damping the body's turn in a push-off. Each hinge of the hips (the
// groups of role hip, both planes) adds kd / 2 times the root's angular velocity about its
// axis to its torque, so that the two legs' hinges together turn the root by -kd w about
// the hips' pitch and roll axes, as SIMBICON's stance hip holds the torso (Yin, Loken, van
// de Panne 2007). It acts on the body's state alone, whichever feet touch, and takes out
// most of the spread of the angular momentum a perturbed push-off leaves the flight with
// (docs/notes/2026-12-07-joint-space-push-off.md). The torque goes through the joint drive
// with the PD's (physics/drive.h): no external force.
//
// Settings: kd (Nm s/rad).
#pragma once

#include <vector>

#include "control/skill_module.h"

namespace diverse {

class RootDampingModule : public SkillModule {
 public:
  RootDampingModule(const ModuleSettings& settings, const Character& body);
  void add_torques(const mjModel* m, const mjData* d, SkillState& s) override;

 private:
  double kd_;
  std::vector<int> hinges_;  // Character::joints indices of the hips' hinges
};

}  // namespace diverse
