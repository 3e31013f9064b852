#include "control/module_stance_support.h"

namespace diverse {

StanceSupportModule::StanceSupportModule(const ModuleSettings& settings, const Character& body)
    : support_(settings.get("support", 1)), middle_(leg_layout(body).middle) {}

void StanceSupportModule::adjust_torques(const mjModel* m, const mjData* d, SkillState& s) {
  if (s.swing < 0 || support_ <= 0) return;
  const Character& body = *s.body;
  const double mass = m->body_subtreemass[body.root_body];
  const double F[3] = {0, 0, support_ * mass * s.gravity};
  for (int k : middle_[static_cast<size_t>(1 - s.swing)]) {
    const CharacterJoint& j = body.joints[static_cast<size_t>(k)];
    const double* a = d->xaxis + 3 * j.joint;
    const double* p = d->xanchor + 3 * j.joint;
    const double r[3] = {s.com[0] - p[0], s.com[1] - p[1], s.com[2] - p[2]};
    double rf[3];
    mju_cross(rf, r, F);
    s.u[static_cast<size_t>(k)] -= a[0] * rf[0] + a[1] * rf[1] + a[2] * rf[2];
  }
}

}  // namespace diverse
