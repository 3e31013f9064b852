// "linear_feedback": a linear feedback from a sensed feature of the body's state to joint
// targets, the form of the balance feedback of SIMBICON (Yin, Loken, van de Panne 2007:
// theta_d = theta_d0 + cd d + cv v) and of the linear feedback policies that stabilize
// flips, rolls and vaults (Liu, Yin, van de Panne, Guo 2012; Ding, Liu, van de Panne, Yin
// 2015): while a phase has it on, the targets of the joints `target` selects become
//   theta_d = theta_d0 + clamp(gain (f - reference), -limit, limit),
// f the feature (control/skill_feature.h): the COM's position or velocity, the root's pitch
// or pitch rate. With sample = 1 f is read once, as the phase begins (a take-off's speed
// held through a flight); with sample = 0 every step. Its gain is usually a parameter the
// optimizer searches with the rest of the motion; at gain 0 the rollout is the one without
// the module, bit for bit.
//
// The offset acts on the joints' targets, in joint angles (for a world-pitch target, the
// same offset of the link's world pitch): where a phase's joints are PD-driven, or a module
// drives them from their targets. List it after a module that sets the same joints'
// targets (a foot_placement's hips) to add to that module's aim.
//
// Settings: feature (a word), target (a selector: a group, role or ROLE.plane), gain (rad
// per unit of the feature), reference (the feature's unit, 0), limit (rad, 1), sample (0).
#pragma once

#include <vector>

#include "control/skill_feature.h"
#include "control/skill_module.h"

namespace diverse {

class LinearFeedbackModule : public SkillModule {
 public:
  LinearFeedbackModule(const SkillModuleSpec& spec, const ModuleSettings& settings, const Character& body);
  void reset(const mjModel* m, const mjData* d, SkillState& s) override;
  void enter(const mjModel* m, const mjData* d, SkillState& s) override;
  void set_targets(const mjModel* m, const mjData* d, SkillState& s) override;
  // The offset (rad) of the last step, for tests and traces.
  double offset() const { return offset_; }

 private:
  SkillFeature feature_ = SkillFeature::kComX;
  double gain_, reference_, limit_;
  bool sample_;
  double sampled_ = 0;   // the feature: as the phase began (sample = 1), or this step's
  bool pending_ = true;  // the phase has begun and the feature is not yet read
  double offset_ = 0;
  std::vector<int> joints_;  // Character::joints indices
};

}  // namespace diverse
