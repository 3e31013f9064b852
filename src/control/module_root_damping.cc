#include "control/module_root_damping.h"

namespace diverse {

RootDampingModule::RootDampingModule(const ModuleSettings& settings, const Character& body) : kd_(settings.get("kd", 0)) {
  for (const JointGroup& g : body.groups)
    if (g.role == JointRole::kHip) hinges_.insert(hinges_.end(), g.joints.begin(), g.joints.end());
}

void RootDampingModule::add_torques(const mjModel* m, const mjData* d, SkillState& s) {
  (void)m;
  const Character& body = *s.body;
  const double* w = d->cvel + 6 * body.root_body;  // the root's angular velocity (world)
  for (int k : hinges_) {
    const double* a = d->xaxis + 3 * body.joints[static_cast<size_t>(k)].joint;
    const double rate = a[0] * w[0] + a[1] * w[1] + a[2] * w[2];
    s.feedforward[static_cast<size_t>(k)] += 0.5 * kd_ * body.strength * rate;
  }
}

}  // namespace diverse
