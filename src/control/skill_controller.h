// The skill engine: one controller that runs any skill file (control/skill_file.h,
// docs/reference/skills.md), registered as the controller type "skill". A task names its skill:
//
//   [controller]
//   skill = "../skills/jump2d.toml"   # relative to the task file
//   landing_height = 0.5              # m, the surface the COM comes down on (default 0)
//   balance = { kp = 4000.0 }         # number settings of the skill's modules, overridden
//
// Each step (after mj_step1), as the phase-based controllers of the paper (section 6,
// figure 4) and of SIMBICON-style controller files (Cartwheel-3D's states with their
// `transitionOn`, DART's atlas_simbicon state machine and terminal conditions):
//  1. the modules of the current phase update what they track (a spotting module the
//     body's turn);
//  2. the phase's transitions are tried in the file's order, at most one taken per step:
//     the first whose conditions all hold; the phase it leads to begins now (and the phases
//     it `passes`), its targets starting from the targets last commanded (in world pitch
//     for its world-frame targets, as the current pose implies them);
//  3. targets: each joint's moves linearly from where the phase began to the phase's goal
//     over the phase's duration (at once without one, or with interpolate = false), or
//     follows the phase's curve; a world-frame target is a link's world pitch, interpolated
//     the shorter way round and turned into a joint target for the current pose; modules
//     may set some joints' targets (a landing the hips);
//  4. torques: a module that drives the phase (stance control) takes over; otherwise every
//     joint is PD-controlled, tau = kp (target - q) - kd qdot + feedforward, the phase's
//     gains times the character's strength, world-frame joints damping their link's world
//     pitch rate, and the feedforward what the modules add (J^T balance). The joint drive
//     keeps the net torque within each joint's limit (physics/drive.h): no external force,
//     the root unactuated.
// The phase durations are a number, a parameter, or predicted from the flight: "rise" v_z
// / g after take-off, "fall" the ballistic time back to take-off height from the peak,
// "touchdown" that time from wherever the phase begins; `at_most` caps a prediction.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "control/controller.h"
#include "control/skill_file.h"
#include "control/skill_module.h"
#include "physics/com_velocity.h"

namespace diverse {

// An angle in [-pi, pi]. Most are already there, and for them remainder(a, 2 pi) is a
// itself (a / 2 pi rounds to 0, ties to even), so the library call is skipped: the same
// bits, at a fraction of the cost.
double skill_wrap(double a);
// World pitch (rad) of joint j's parent link (planar characters).
double skill_parent_pitch(const Character& body, int j, const double* qpos);

struct SkillConfig : ControllerConfig {
  std::shared_ptr<const SkillFile> skill;
  double landing_height_m = 0;  // m
  std::shared_ptr<const ControllerConfig> with_landing_height(double height) const override;
  double landing_height() const override { return landing_height_m; }
  std::string skill_name() const override { return skill->name; }
  // The skill bound to a character's structure, made once per character file.
  std::shared_ptr<const SkillBinding> binding(const Character& body) const;

 private:
  mutable std::mutex mutex_;
  mutable std::vector<std::pair<const CharacterSpec*, std::shared_ptr<const SkillBinding>>> bindings_;
};

class SkillControllerType : public ControllerType {
 public:
  const char* name() const override { return "skill"; }
  const char* description() const override { return "the skill engine: runs the phases of a skill file (skills/)"; }
  const char* skill(const ControllerConfig& config) const override;
  std::shared_ptr<const ControllerConfig> read_config(const TomlReader& r) const override;
  void check(const Character& body, const std::string& task_file) const override;
  // Binds the skill to the character (bind_skill): a group, role or body it does not
  // have, or another root, is the skill file's error line.
  void check(const Character& body, const ControllerConfig& config, const std::string& task_file) const override;
  std::vector<ParamSpec> parameter_specs(const Character& body, const ControllerConfig& config) const override;
  std::unique_ptr<Controller> make(const Character& body, const ControllerConfig& config,
                                   const std::vector<double>& values) const override;
};

class SkillController : public Controller {
 public:
  // `values` in binding->params order.
  SkillController(const Character& body, const SkillConfig& config, std::shared_ptr<const SkillBinding> binding,
                  const std::vector<double>& values);

  // With start = "first_phase" (free roots): the rollout starts static in the first
  // phase's pose, heading along world x: the root at its pitch and roll, every joint at its
  // target, every heading-frame link at its target (without the modules' feedback), the
  // stance foot at its standing orientation and its sole on the floor below the root.
  bool start_state(const mjModel* m, mjData* d) override;
  void reset(const mjModel* m, const mjData* d) override;
  void control(const mjModel* m, mjData* d, const ContactState& contacts, JointDrive& drive) override;

  int phase() const override { return state_.phase; }
  bool phase_changed() const override { return state_.phase_changed; }
  const PhaseTimes& phase_times() const override { return times_; }
  int swing_leg(int phase) const override { return binding_->phases[static_cast<size_t>(phase)].swing; }
  bool gave_up() const override { return gave_up_; }
  const std::array<double, 3>& com() const override { return state_.com; }
  const std::array<double, 3>& com_velocity() const override { return state_.com_vel; }
  // Joint targets (rad) commanded in the last step, one per Character::joints entry.
  const std::vector<double>& targets() const { return state_.target; }

 private:
  bool holds(const SkillCondition& c, const mjModel* m, const mjData* d) const;
  void enter(int phase, const mjModel* m, const mjData* d);
  void load_goals(const SkillPhaseBinding& pb);
  double duration_of(int phase) const;
  double to_local(size_t j, const double* qpos, double world) const;
  double to_world(size_t j, const double* qpos, double local) const;
  SkillTarget::World world(size_t j) const;
  void prepare(const mjModel* m);  // the standing frames and heading-frame links, once
  // The world orientation target of the heading-frame link on MuJoCo body `b`.
  void link_target(int b, double* quat) const;

  const Character& body_;
  std::shared_ptr<const SkillFile> skill_;
  std::shared_ptr<const SkillBinding> binding_;
  std::vector<double> values_;
  std::vector<std::unique_ptr<SkillModule>> modules_;  // per SkillFile::modules entry
  int takeoff_ = -1;                                    // the take-off phase
  SkillState state_;
  ContactState contacts_;
  PhaseTimes times_;
  bool gave_up_ = false;
  double free_since_ = -1;    // liftoff: time contact was last lost, -1 if touching
  double takeoff_pitch_ = 0;  // root pitch at take-off (rad)
  std::vector<std::pair<const SkillCondition*, int>> bodies_;  // conditions' bodies: MuJoCo ids
  std::vector<double> qpos0_;      // per joint: its angle in the standing pose
  std::vector<char> liftoff_;                // per phase: a transition waits for a lift-off
  std::vector<std::vector<char>> owned_;     // per phase, per joint: a module writes its target
  std::vector<DampedDof> damped_;  // scratch: a tracked joint's damped velocity
  SubtreeComVelocity com_velocity_;  // of the character's subtree, set by reset()
  // Free roots: whether any phase tracks the root or a link in the heading frame, the
  // model's standing frames and, per MuJoCo body, its link (body -1 when it has no hinge).
  bool heading_frame_ = false, prepared_ = false;
  StandingFrames standing_;
  std::vector<HeadingLink> links_;
  std::vector<char> link_done_;      // per MuJoCo body: its error computed this step
  std::vector<std::array<double, 3>> link_error_;  // per MuJoCo body: rotation error (world)
  std::vector<char> preset_;         // per joint: already given to the drive this step
};

}  // namespace diverse
