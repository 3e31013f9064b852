// "stance": the phase's torques by stance control (control/stance_controller.h), as a
// landing: the J^T force on the COM held so that its centre of pressure stays inside the
// soles (F_z carrying the weight, no height servo, so the joint targets decide how low the
// body goes), the pelvis's world pitch held through the stance legs, the feet tracking
// theirs and the chest tracked with the waist. The pelvis, chest and foot goals of the
// phase's targets (the groups hip, waist.top and ankle) become those links' world
// pitches, reached over the phase from where they were when it began; the other joints
// follow the phase's targets. The phase's gains drive the knees, the feet's and the chest's
// tracking; the root keeps the stance controller's own gains, 2 M g h0 (a landing's hip
// gains made it chatter).
//
// stand_after (s, >= 0): this long after the phase's pose is reached, stand up from it over
// stand_duration, to the tracked links level and every other joint at the model's qpos0,
// instead of holding a deep crouch until it gives way; < 0 (the default): hold it.
//
// Settings: offset (m, where the COM is held ahead of the soles' centre; default 0),
// stand_after (s, default -1), stand_duration (s, default 0.5).
#pragma once

#include <memory>

#include "control/skill_module.h"
#include "control/stance_controller.h"

namespace diverse {

class StanceModule : public SkillModule {
 public:
  StanceModule(const ModuleSettings& settings, const Character& body);
  void reset(const mjModel* m, const mjData* d, SkillState& s) override;
  void enter(const mjModel* m, const mjData* d, SkillState& s) override;
  bool drives() const override { return true; }
  void drive(const mjModel* m, const mjData* d, SkillState& s, JointDrive& drive) override;

 private:
  double offset_, stand_after_, stand_duration_;
  int pelvis_ = -1, chest_ = -1, foot_ = -1;  // a joint of the hip, waist.top and ankle groups
  std::unique_ptr<StanceController> stance_;
  std::array<double, 3> from_{}, goal_{};  // world pitches: root, torso, feet
};

}  // namespace diverse
