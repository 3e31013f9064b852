#include "control/module_balance.h"

#include <algorithm>

namespace diverse {

BalanceModule::BalanceModule(const ModuleSettings& settings, const Character& body)
    : kp_(settings.get("kp", 0)),
      kd_(settings.get("kd", 0)),
      max_force_(settings.get("max_force", 0)),
      gravity_compensation_(settings.get("gravity_compensation", 1)),
      offset_(settings.get("offset", 0)),
      lean_(settings.get("lean", 0)) {
  for (const char* role : {"ankle", "knee", "hip"}) {
    for (int g : select_groups(role, body)) {
      for (int j : body.groups[static_cast<size_t>(g)].joints) legs_.push_back(j);
    }
  }
}

void BalanceModule::add_torques(const mjModel* m, const mjData* d, SkillState& s) {
  (void)m;
  if (!s.contacts->any) return;
  const Character& body = *s.body;
  const int* feet = body.feet.data();
  const double support = 0.5 * (d->xipos[3 * feet[0]] + d->xipos[3 * feet[1]]);
  double target = support + offset_, speed = 0;
  if (lean_ > 0) {  // lead the COM along the lean
    const double duration = std::max(s.phase_duration, 1e-6);
    target += std::clamp((s.time - s.phase_begin) / duration, 0.0, 1.0) * lean_;
    speed = lean_ / duration;
  }
  const double fx = std::clamp(kp_ * (target - s.com[0]) + kd_ * (speed - s.com_vel[0]), -max_force_, max_force_);
  const double fz = gravity_compensation_ * body.total_mass * s.gravity;
  for (int i : legs_) {
    const double* p = d->xanchor + 3 * body.joints[static_cast<size_t>(i)].joint;
    const double rx = s.com[0] - p[0], rz = s.com[2] - p[2];
    s.feedforward[static_cast<size_t>(i)] = -0.5 * (rx * fz - rz * fx);
  }
}

}  // namespace diverse
