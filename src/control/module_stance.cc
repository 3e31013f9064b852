#include "control/module_stance.h"

#include <algorithm>
#include <cmath>

namespace diverse {
namespace {

int first_joint(const std::string& selector, const Character& body) {
  const auto groups = select_groups(selector, body);
  return groups.empty() ? -1 : body.groups[static_cast<size_t>(groups[0])].joints[0];
}

}  // namespace

StanceModule::StanceModule(const ModuleSettings& settings, const Character& body)
    : offset_(settings.get("offset", 0)),
      stand_after_(settings.get("stand_after", -1)),
      stand_duration_(settings.get("stand_duration", 0.5)),
      pelvis_(first_joint("hip", body)),
      chest_(first_joint("waist.top", body)),
      foot_(first_joint("ankle", body)) {}

void StanceModule::reset(const mjModel* m, const mjData* d, SkillState& s) {
  (void)d;
  stance_ = std::make_unique<StanceController>(*s.body, m);
}

// The world pitches to move from (as the stance controller measures them) and to, and the
// gains.
void StanceModule::enter(const mjModel* m, const mjData* d, SkillState& s) {
  stance_->reset(m, d);  // the heading and footing the phase begins with
  const StanceController::Pitches p = stance_->measured_pitches(d);
  from_ = {p.root, p.torso, p.foot};
  const double root = s.goal[static_cast<size_t>(pelvis_)];
  const double torso = chest_ >= 0 ? s.goal[static_cast<size_t>(chest_)] : root;
  goal_ = {root, torso, s.goal[static_cast<size_t>(foot_)]};
  // The strength model scales every joint's PD gains (Character::strength).
  for (size_t i = 0; i < s.body->joints.size(); ++i) {
    stance_->set_joint_gains(static_cast<int>(i), s.body->strength * s.kp[i], s.body->strength * s.kd[i]);
  }
  const double h = stance_->heading();
  stance_->set_com_offset(offset_ * std::cos(h), offset_ * std::sin(h));
  stance_->set_com_velocity(0, 0);
  stance_->set_com_force(StanceController::ComForce::kSupport);
}

void StanceModule::drive(const mjModel* m, const mjData* d, SkillState& s, JointDrive& drive) {
  // stand_after: a fraction u of the way on from the phase's pose to standing.
  double u = 0;
  if (stand_after_ >= 0) {
    u = std::clamp((d->time - s.phase_begin - s.phase_duration - stand_after_) / stand_duration_, 0.0, 1.0);
  }
  auto at = [&](size_t k) {
    const double pitch = from_[k] + s.progress * (goal_[k] - from_[k]);
    return (1 - u) * pitch;
  };
  stance_->set_pitches(at(0), at(1), at(2));
  if (u > 0) {
    for (size_t i = 0; i < s.target.size(); ++i) s.target[i] += u * (m->qpos0[s.body->joints[i].qpos] - s.target[i]);
  }
  stance_->set_targets(s.target);
  stance_->control(m, d, drive);
}

}  // namespace diverse
