// "stance_support": the stance leg carries the body. The stance leg's joints between its
// hip and its foot (the knee; the bird's ankle) add the Jacobian-transpose torques of an
// upward force F = support M g on the COM with the foot as the base (Pratt et al. 2001's
// virtual model control), tau_j -= a_j . ((c - p_j) x F) (a_j the joint's world axis, p_j
// its anchor, c the COM). With it a walk's stance knee need not bend under the body
// before its PD gains hold it.
//
// Settings: support (the share of the weight, 1 the whole). Phases with a swing leg.
#pragma once

#include "control/heading_frame.h"
#include "control/skill_module.h"

namespace diverse {

class StanceSupportModule : public SkillModule {
 public:
  StanceSupportModule(const ModuleSettings& settings, const Character& body);
  void adjust_torques(const mjModel* m, const mjData* d, SkillState& s) override;

 private:
  double support_;
  std::array<std::vector<int>, 2> middle_;  // per leg: joints between the hip and the foot
};

}  // namespace diverse
