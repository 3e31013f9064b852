#include "control/module_foot_placement.h"

#include <algorithm>
#include <cmath>

#include "control/skill_controller.h"

namespace diverse {

FootPlacementModule::FootPlacementModule(const ModuleSettings& settings, const Character& body)
    : offset_(settings.get("offset", 0)),
      velocity_gain_(settings.get("velocity_gain", 0)),
      reach_(settings.get("reach", 0)),
      at_touchdown_(settings.get("at_touchdown", 0) != 0) {
  hip_ = select_groups("hip", body).at(0);
  knee_ = select_groups("knee", body).at(0);
  const int ankle = select_groups("ankle", body).at(0);
  auto distance = [&](int a, int b) {
    const auto& p = body.joints[static_cast<size_t>(a)].anchor0;
    const auto& q = body.joints[static_cast<size_t>(b)].anchor0;
    return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
  };
  const int hip0 = body.groups[static_cast<size_t>(hip_)].joints[0];
  const int knee0 = body.groups[static_cast<size_t>(knee_)].joints[0];
  const int ankle0 = body.groups[static_cast<size_t>(ankle)].joints[0];
  thigh_length_ = distance(hip0, knee0);
  shin_length_ = distance(knee0, ankle0);
  hips_ = body.groups[static_cast<size_t>(hip_)].joints;
}

void FootPlacementModule::reset(const mjModel* m, const mjData* d, SkillState& s) {
  (void)m;
  // Standing: the COM's height above the floor, and how far ahead of the ankle each sole's
  // middle (the foot's centre of mass) lies.
  standing_com_z_ = d->subtree_com[3 * s.body->root_body + 2];
  sole_ahead_ = 0;
  for (int f : s.body->feet) sole_ahead_ += 0.5 * (d->xipos[3 * f] - d->xpos[3 * f]);
}

bool FootPlacementModule::owns_target(int joint) const {
  return std::find(hips_.begin(), hips_.end(), joint) != hips_.end();
}

double FootPlacementModule::hip_goal(int j, const mjData* d, const SkillState& s) const {
  const Character& body = *s.body;
  const CharacterJoint& hip = body.joints[static_cast<size_t>(j)];
  const int side = hip.side == Side::kRight ? 1 : 0;
  const double above = at_touchdown_ ? standing_com_z_ : 0.0;
  const double z = std::max(s.com[2] - s.landing_height - above, 0.0);
  const double vz = s.com_vel[2];
  const double t_cross = (vz + std::sqrt(vz * vz + 2 * s.gravity * z)) / s.gravity;
  const double sole = at_touchdown_ ? sole_ahead_ : 0.0;
  const double x_target = s.com[0] + s.com_vel[0] * t_cross - sole + offset_ + velocity_gain_ * s.com_vel[0];
  const double dx = x_target - d->xanchor[3 * hip.joint];
  // Two-link leg: ankle x offset = l1 sin(th) + l2 sin(th + qk) = R sin(th + psi).
  const int knee = body.groups[static_cast<size_t>(knee_)].joints[static_cast<size_t>(side)];
  const double qk = s.target[static_cast<size_t>(knee)];
  const double a = thigh_length_ + shin_length_ * std::cos(qk);
  const double b = shin_length_ * std::sin(qk);
  const double thigh = std::asin(std::clamp(dx / std::hypot(a, b), -0.9, 0.9)) - std::atan2(b, a);
  return skill_wrap(thigh - skill_parent_pitch(body, j, d->qpos));
}

void FootPlacementModule::set_targets(const mjModel* m, const mjData* d, SkillState& s) {
  (void)m;
  const double pelvis = s.qpos[s.body->root_pitch_qpos];
  const double w = std::clamp((std::cos(pelvis) - 0.5) / 0.5, 0.0, 1.0);
  for (int i : hips_) {
    const size_t k = static_cast<size_t>(i);
    double goal = s.goal[k];
    if (w > 0) goal = (1 - w) * goal + w * hip_goal(i, d, s);
    // How far along from the phase's first hip angle to the goal (reach: reached early).
    const double along = reach_ > 0 ? std::min(1.0, (s.time - s.phase_begin) / reach_) : s.progress;
    s.target[k] = s.from[k] + along * (goal - s.from[k]);
  }
}

}  // namespace diverse
