// "stance3d": a phase's torques by stance control of a character with a free root
// (control/stance_controller.h): a Jacobian-transpose virtual force on the COM (Pratt et
// al. 2001) through the stance legs, which also hold the root's world orientation; the
// torso and the soles track world orientations; every other joint is PD toward the
// phase's targets. The phase's targets with world = "root", "torso" and "sole" are those
// links' world pitches about the heading's lateral axis (rad, positive backwards, 0 =
// standing; a sole's per side, the torso's the root's when the phase has none); their
// joints hold the angles of the last phase that began from the pose (a swing hip keeps
// its place). A phase that begins from the pose (from = "pose") starts the pitches from
// the measured ones (the soles from their mean).
//
// Gains: the phase's gains of every joint (for a sole's joint those of the sole's world
// tracking, for the torso's those of the torso's); the root's orientation gains are the
// sum of the phase's gains of the joints with world = "root" (the two hips).
//
// Settings: offset (m, the COM held this far ahead of the soles' centre along the heading;
// 0), speed (m/s, the horizontal COM speed along the heading the force's damping drives
// toward; 0), push (1: the COM force is not held to the support polygon, the feet may tip,
// as a take-off's; 0), take_footing (1: the heading and COM height are taken as each of the
// module's phases begins, as a landing's; 0: once, as the motion begins), com_kp, com_kd
// (1/s^2, 1/s; 40, 12), yaw_kp, yaw_kd (Nm/rad, Nm s/rad; 0, 0: the stance legs hold the
// root's yaw, StanceGains).
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "control/skill_module.h"
#include "control/stance_controller.h"

namespace diverse {

class Stance3dModule : public SkillModule {
 public:
  Stance3dModule(const ModuleSettings& settings, const Character& body);
  void reset(const mjModel* m, const mjData* d, SkillState& s) override;
  void enter(const mjModel* m, const mjData* d, SkillState& s) override;
  void set_targets(const mjModel* m, const mjData* d, SkillState& s) override;
  bool drives() const override { return true; }
  void drive(const mjModel* m, const mjData* d, SkillState& s, JointDrive& drive) override;

 private:
  double offset_, speed_;
  bool push_, take_footing_;
  StanceGains gains_;
  std::unique_ptr<StanceController> stance_;
  // The current phase's joints with world-frame targets: root, torso, soles (left, right).
  std::vector<int> root_, torso_;
  std::array<int, 2> sole_{-1, -1};
  double root_pitch_ = 0, torso_pitch_ = 0;
  std::array<double, 2> sole_pitch_{0, 0};
};

}  // namespace diverse
