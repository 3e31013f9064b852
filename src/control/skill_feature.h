// Features of the body's state a skill file names: a transition's `on = "feature"` and a
// `linear_feedback` module's input (docs/reference/skills.md).
//
//   double v = skill_feature(SkillFeature::kComVx, body, d, com, com_vel);
//
// com_x, com_z (m) and com_vx, com_vz (m/s) are the whole-body COM along world x and up;
// pitch (rad, positive backwards, 0 standing) and pitch_rate (rad/s) are the root's: a
// planar root's pitch coordinate and its rate, or a free root's tilt about the heading
// frame's lateral axis (control/heading_frame.h) relative to its orientation in the
// model's standing pose, and its angular velocity about that axis.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <string>
#include <vector>

#include "character/character.h"

namespace diverse {

enum class SkillFeature { kComX, kComZ, kComVx, kComVz, kPitch, kPitchRate };

// The names a skill file uses, in SkillFeature order.
const std::vector<std::string>& skill_feature_names();
// The feature called `name`; false if there is none.
bool skill_feature_of(const std::string& name, SkillFeature* out);

// The feature's value in state d (after mj_kinematics and mj_comVel), `com` and `com_vel`
// the whole-body COM and its velocity.
double skill_feature(SkillFeature f, const Character& body, const mjModel* m, const mjData* d,
                     const std::array<double, 3>& com, const std::array<double, 3>& com_vel);

}  // namespace diverse
