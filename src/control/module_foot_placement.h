// "foot_placement": the paper's landing controller (section 6, 2D). While the pelvis is
// within 60 degrees of upright, the hips place each ankle horizontally at
// x_c + offset + velocity_gain * v_x, x_c where the COM is predicted to cross the landing
// surface on its ballistic path; the hip angle comes from the two-link leg (hip-knee and
// knee-ankle distances of the standing model) with the knee at this step's target. The
// weight w = clamp((cos pelvis - 0.5) / 0.5, 0, 1) blends the phase's own hip goal into
// this one, and the hips move from where the phase began to the blend over the phase.
//
// at_touchdown (0 or 1): x_c is where the COM will be when it has come down to its standing
// height above the surface, less the soles' lead over the ankles, so that with offset and
// gain 0 the COM comes down over the middle of the soles (the paper's x_c overshoots, and
// the offset that makes up for it holds only for the pitch the input motion lands with).
// reach (s, > 0): the hips reach the goal this long after the phase began and then follow
// it; 0: over the whole phase.
//
// Settings: offset (m), velocity_gain (s), reach (s, default 0), at_touchdown (default 0).
// The landing surface's height is the task's (`landing_height`). Planar characters.
#pragma once

#include "control/skill_module.h"

namespace diverse {

class FootPlacementModule : public SkillModule {
 public:
  FootPlacementModule(const ModuleSettings& settings, const Character& body);
  void reset(const mjModel* m, const mjData* d, SkillState& s) override;
  bool owns_target(int joint) const override;
  void set_targets(const mjModel* m, const mjData* d, SkillState& s) override;

 private:
  double hip_goal(int j, const mjData* d, const SkillState& s) const;

  double offset_, velocity_gain_, reach_;
  bool at_touchdown_;
  int hip_ = -1, knee_ = -1;
  std::vector<int> hips_;  // the hip group's joints
  double thigh_length_ = 0, shin_length_ = 0;  // m, hip-knee and knee-ankle at qpos0
  double standing_com_z_ = 0;  // m, the COM's height at reset()
  double sole_ahead_ = 0;      // m, the soles' middles ahead of the ankles at reset()
};

}  // namespace diverse
