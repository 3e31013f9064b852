#include "control/module_stance3d.h"

#include <cmath>

namespace diverse {

Stance3dModule::Stance3dModule(const ModuleSettings& settings, const Character& body)
    : offset_(settings.get("offset", 0)),
      speed_(settings.get("speed", 0)),
      push_(settings.get("push", 0) != 0),
      take_footing_(settings.get("take_footing", 0) != 0) {
  (void)body;
  gains_.com_kp = settings.get("com_kp", gains_.com_kp);
  gains_.com_kd = settings.get("com_kd", gains_.com_kd);
  gains_.yaw_kp = settings.get("yaw_kp", gains_.yaw_kp);
  gains_.yaw_kd = settings.get("yaw_kd", gains_.yaw_kd);
}

void Stance3dModule::reset(const mjModel* m, const mjData* d, SkillState& s) {
  stance_ = std::make_unique<StanceController>(*s.body, m, gains_);
  stance_->reset(m, d);
}

void Stance3dModule::enter(const mjModel* m, const mjData* d, SkillState& s) {
  if (take_footing_) stance_->reset(m, d);  // the heading and footing the phase begins with
  const Character& body = *s.body;
  root_.clear();
  torso_.clear();
  sole_ = {-1, -1};
  for (size_t i = 0; i < body.joints.size(); ++i) {
    switch ((*s.targets)[i].world) {
      case SkillTarget::World::kRoot: root_.push_back(static_cast<int>(i)); break;
      case SkillTarget::World::kTorso: torso_.push_back(static_cast<int>(i)); break;
      case SkillTarget::World::kSole: sole_[body.joints[i].side == Side::kRight ? 1 : 0] = static_cast<int>(i); break;
      default: break;
    }
  }
  if (s.from_pose) {  // the pitches start where the body is
    const StanceController::Pitches p = stance_->measured_pitches(d);
    for (int k : root_) s.from[static_cast<size_t>(k)] = p.root;
    for (int k : torso_) s.from[static_cast<size_t>(k)] = p.torso;
    for (int k : sole_)
      if (k >= 0) s.from[static_cast<size_t>(k)] = p.foot;  // both soles from their mean
  }
  // The strength model scales every joint's PD gains (Character::strength).
  const double strength = body.strength;
  for (size_t i = 0; i < body.joints.size(); ++i) stance_->set_joint_gains(static_cast<int>(i), strength * s.kp[i], strength * s.kd[i]);
  if (!root_.empty()) {
    // The root is turned through the stance hips: their gains add up (x + x is 2 x).
    double kp = 0, kd = 0;
    for (int k : root_) {
      kp += s.kp[static_cast<size_t>(k)];
      kd += s.kd[static_cast<size_t>(k)];
    }
    stance_->set_root_gains(kp, kd);
  }
  const double h = stance_->heading();
  stance_->set_com_offset(offset_ * std::cos(h), offset_ * std::sin(h));
  stance_->set_com_velocity(speed_ * std::cos(h), speed_ * std::sin(h));
  stance_->set_com_force(push_ ? StanceController::ComForce::kPush : StanceController::ComForce::kSupport);
}

void Stance3dModule::set_targets(const mjModel* m, const mjData* d, SkillState& s) {
  (void)m, (void)d;
  // The world pitches the engine interpolated; their joints hold their angles.
  if (!root_.empty()) root_pitch_ = s.target[static_cast<size_t>(root_[0])];
  torso_pitch_ = torso_.empty() ? root_pitch_ : s.target[static_cast<size_t>(torso_[0])];
  for (size_t side = 0; side < 2; ++side)
    if (sole_[side] >= 0) sole_pitch_[side] = s.target[static_cast<size_t>(sole_[side])];
  for (const auto* joints : {&root_, &torso_})
    for (int k : *joints) s.target[static_cast<size_t>(k)] = s.hold[static_cast<size_t>(k)];
  for (int k : sole_)
    if (k >= 0) s.target[static_cast<size_t>(k)] = s.hold[static_cast<size_t>(k)];
}

void Stance3dModule::drive(const mjModel* m, const mjData* d, SkillState& s, JointDrive& drive) {
  stance_->set_pitches(root_pitch_, torso_pitch_, sole_pitch_);
  stance_->set_targets(s.target);
  stance_->control(m, d, drive);
}

}  // namespace diverse
