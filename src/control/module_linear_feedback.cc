#include "control/module_linear_feedback.h"

#include <algorithm>

namespace diverse {

LinearFeedbackModule::LinearFeedbackModule(const SkillModuleSpec& spec, const ModuleSettings& settings, const Character& body)
    : gain_(settings.get("gain", 0)),
      reference_(settings.get("reference", 0)),
      limit_(settings.get("limit", 1.0)),
      sample_(settings.get("sample", 0) > 0.5) {
  skill_feature_of(spec.words.at("feature"), &feature_);
  for (int g : select_groups(spec.words.at("target"), body)) {
    const auto& joints = body.groups[static_cast<size_t>(g)].joints;
    joints_.insert(joints_.end(), joints.begin(), joints.end());
  }
}

void LinearFeedbackModule::reset(const mjModel* m, const mjData* d, SkillState& s) {
  (void)m, (void)d, (void)s;
  pending_ = true;  // a module of the first phase reads the feature in the first step
}

void LinearFeedbackModule::enter(const mjModel* m, const mjData* d, SkillState& s) {
  (void)m, (void)d, (void)s;
  pending_ = true;
}

void LinearFeedbackModule::set_targets(const mjModel* m, const mjData* d, SkillState& s) {
  if (!sample_ || pending_) {
    sampled_ = skill_feature(feature_, *s.body, m, d, s.com, s.com_vel);
    pending_ = false;
  }
  const double f = sampled_;
  offset_ = std::clamp(gain_ * (f - reference_), -limit_, limit_);
  if (offset_ == 0) return;  // gain 0: the targets as without the module, bit for bit
  for (int j : joints_) s.target[static_cast<size_t>(j)] += offset_;
}

}  // namespace diverse
