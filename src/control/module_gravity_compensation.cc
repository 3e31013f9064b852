#include "control/module_gravity_compensation.h"

namespace diverse {

GravityCompensationModule::GravityCompensationModule(const Character& body) : leg_of_(leg_layout(body).leg_of) {}

void GravityCompensationModule::adjust_torques(const mjModel* m, const mjData* d, SkillState& s) {
  const Character& body = *s.body;
  const int stance = s.swing >= 0 ? 1 - s.swing : -1;
  for (size_t k = 0; k < body.joints.size(); ++k) {
    const int leg = leg_of_[k];
    if (leg >= 0) {
      // In a phase with a swing leg, its stance leg and, in double support, the swing leg;
      // otherwise every leg whose foot touches something.
      const bool carries = s.swing >= 0 ? leg == stance || (s.double_support && leg == s.swing)
                                        : s.contacts->foot[static_cast<size_t>(leg)];
      if (carries) continue;
    }
    s.u[k] += gravity_torque(m, d, body.joints[k], s.gravity);
  }
}

}  // namespace diverse
