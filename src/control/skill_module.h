// Feedback modules of the skill engine (control/skill_controller.h): small components a
// skill file's phase switches on by name ([[modules]] in docs/reference/skills.md). Each kind lives
// in its own control/module_KIND.{h,cc} with the paper it comes from.
//
// The engine calls, in one control step: update() for the modules of the current phase
// (before the transitions), then, on a transition, enter() for the modules of the phase
// just begun; then set_targets() (after the engine's own targets), and last either
// drive() for a module that takes the torques over (drives() true) or add_torques() into
// the per-joint feedforward the PD torques add, and then adjust_torques() on the torques
// the engine is about to ask for (SkillState::u, damping), in the phase's module order.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "character/character.h"
#include "control/controller.h"
#include "control/heading_frame.h"
#include "control/skill_file.h"
#include "physics/drive.h"

namespace diverse {

// What the engine knows in the current step; modules read it and write targets and
// feedforward torques.
struct SkillState {
  const Character* body = nullptr;
  const ContactState* contacts = nullptr;
  double time = 0;                             // s
  const double* qpos = nullptr;
  std::array<double, 3> com{}, com_vel{};      // whole-body COM (m) and its velocity (m/s)
  double gravity = 9.81;                       // m/s^2
  double landing_height = 0;                   // m, the surface the COM comes down on
  int phase = 0;
  bool phase_changed = false;
  double phase_begin = 0, phase_duration = 1;  // s
  double progress = 0;                         // through the phase's targets, 0..1
  double takeoff_com_z = 0;                    // m, at the take-off event
  std::vector<double> target;       // per joint: this step's target (rad)
  std::vector<double> from;         // per joint: where the phase's targets start
  std::vector<double> goal;         // per joint: the phase's goal (rad; world pitch if tracked)
  std::vector<double> kp, kd;       // per joint: the phase's gains, before strength
  std::vector<double> hold;         // per joint: its angle when the last phase from the pose began
  bool from_pose = false;           // the current phase began from the pose (from = "pose")
  const std::vector<SkillJointTarget>* targets = nullptr;  // the current phase's, per joint
  std::vector<double> feedforward;  // per joint: torque the PD adds (Nm), 0 each step
  // Free roots (control/heading_frame.h).
  int swing = -1;                     // the phase's swinging leg (0 left, 1 right), -1 none
  // Both feet down in a phase with a swing leg: the swing foot still touches the ground
  // (early in a step). A phase that ends when the swing foot comes down is never in double
  // support: the touch-down ends it.
  bool double_support = false;
  double heading = 0;                 // rad, the root's heading this step
  bool root = false;                  // the phase gives the root's pitch and roll
  double root_pitch = 0, root_roll = 0;  // rad, in the heading frame (mirrored when given so)
  const StandingFrames* standing = nullptr;  // the model's standing pose
  // The torques about to be asked for: per joint u (Nm, all but the joint's own damping)
  // and the damping gain kd (Nm s/rad), the drive applying u - kd qdot within the limit.
  std::vector<double> u, damping;
  // Scratch a module may share with the others of the phase in one step: the COM velocity
  // as the sum of the links' momenta (module_simbicon.h) and the time it was computed at.
  std::array<double, 3> link_com_vel{};
  double link_com_vel_time = -1;
};

class SkillModule {
 public:
  virtual ~SkillModule() = default;
  virtual void reset(const mjModel* m, const mjData* d, SkillState& s) {
    (void)m, (void)d, (void)s;
  }
  virtual void enter(const mjModel* m, const mjData* d, SkillState& s) {
    (void)m, (void)d, (void)s;
  }
  virtual void update(const mjModel* m, const mjData* d, SkillState& s) {
    (void)m, (void)d, (void)s;
  }
  // The "spotted" transition condition (spotting modules).
  virtual bool spotted(const SkillState& s) const {
    (void)s;
    return false;
  }
  // Joints whose targets set_targets() writes (the engine leaves them alone).
  virtual bool owns_target(int joint) const {
    (void)joint;
    return false;
  }
  virtual void set_targets(const mjModel* m, const mjData* d, SkillState& s) {
    (void)m, (void)d, (void)s;
  }
  virtual void add_torques(const mjModel* m, const mjData* d, SkillState& s) {
    (void)m, (void)d, (void)s;
  }
  virtual void adjust_torques(const mjModel* m, const mjData* d, SkillState& s) {
    (void)m, (void)d, (void)s;
  }
  virtual bool drives() const { return false; }
  virtual void drive(const mjModel* m, const mjData* d, SkillState& s, JointDrive& drive) {
    (void)m, (void)d, (void)s, (void)drive;
  }
};

// A module's settings with this rollout's parameter values in place of parameters.
class ModuleSettings {
 public:
  ModuleSettings(const SkillModuleSpec& spec, const std::map<std::string, int>& params,
                 const std::vector<double>& values);
  double get(const std::string& name, double fallback) const;

 private:
  std::map<std::string, double> values_;
};

// One module of `spec.kind` for one rollout.
std::unique_ptr<SkillModule> make_skill_module(const SkillModuleSpec& spec, const ModuleSettings& settings,
                                               const Character& body);

}  // namespace diverse
