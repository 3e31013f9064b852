// "simbicon": SIMBICON's balance feedback (Yin, Loken, van de Panne 2007, section 3.2), in
// one plane. While a leg swings, the swing hip's heading-frame target in that plane
// (control/heading_frame.h) becomes
//   theta_d = theta_d0 + cd d + cv v,
// d the horizontal distance from the stance foot's origin (the human's ankle, the bird's
// toe joint) to the COM and v the COM's velocity, in the heading frame: along the heading
// (plane = "sagittal"), or sideways measured toward the swing side (plane = "coronal").
// A walk that leans or drifts ahead steps further ahead, one drifting toward the swing
// side steps out wider: the foot placement that keeps a walk upright.
//
// v is the sum of the links' momenta over the total mass, in link order (as the walk
// measured it before it was a skill file; the engine's own COM velocity sums the same
// momenta in MuJoCo's order, which differs in the last bits).
//
// Settings: plane ("sagittal" or "coronal"), cd (rad/m), cv (rad s/m). Free roots.
#pragma once

#include "control/heading_frame.h"
#include "control/skill_module.h"

namespace diverse {

class SimbiconModule : public SkillModule {
 public:
  SimbiconModule(const SkillModuleSpec& spec, const ModuleSettings& settings, const Character& body);
  void set_targets(const mjModel* m, const mjData* d, SkillState& s) override;

 private:
  bool coronal_;
  double cd_, cv_;
  std::array<std::vector<int>, 2> hips_;  // per leg: the hip's hinges in this plane
};

}  // namespace diverse
