// "gravity_compensation": every joint that does not carry the body from the ground holds
// the links it carries against gravity, tau_j += a_j . ((c_sub - p_j) x m_sub g z) (a_j
// its world axis, p_j its anchor, c_sub and m_sub the COM and mass of the links below it;
// control/heading_frame.h), so that the PD gains need not: SIMBICON's swing leg tracks its
// targets with low gains (Yin, Loken, van de Panne 2007, section 3.1; Coros et al. 2010's
// Cartwheel-3D uses the same compensation). The joints of a leg in stance (the phase's
// stance leg, or the swing leg while it still touches the ground, double support) carry
// the body instead and are left alone.
//
// No settings.
#pragma once

#include "control/heading_frame.h"
#include "control/skill_module.h"

namespace diverse {

class GravityCompensationModule : public SkillModule {
 public:
  explicit GravityCompensationModule(const Character& body);
  void adjust_torques(const mjModel* m, const mjData* d, SkillState& s) override;

 private:
  std::vector<int> leg_of_;  // per joint: 0, 1 or -1
};

}  // namespace diverse
