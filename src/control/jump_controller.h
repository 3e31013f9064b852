// "jump2d": the phase-based jump controller for planar characters (paper section 6,
// figure 4), registered in control/builtin_controllers.cc.
//
// A finite state machine over six phases:
//
//   start   stance, balance, ends after start.duration
//   crouch  stance, ends after crouch.duration (with the config's crouch_lean the balance
//           servo leads the COM along a lean ahead of the feet instead of holding it)
//   extend  stance, targets applied at once (no interpolation) to build momentum,
//           ends when the character is airborne (no contact with anything for
//           airborne_time, COM rising)
//   rise    flight, ends at peak height (COM vertical velocity <= 0), or with the config's
//           open_rotation once the root has also turned that far since take-off, with its
//           open_turn once the body, opened now, would turn that far by touch-down; duration
//           predicted as v_z / g at take-off (targets reached sooner with tuck_time)
//   fall    flight, ends at the first contact; duration predicted as the ballistic time
//           back to take-off height, sqrt(2 (z_peak - z_takeoff) / g) from the peak (from
//           the current height and fall speed when open_rotation or open_turn ends the rise later;
//           targets reached sooner with open_time); optional landing controller (below)
//   land    stance, balance, targets interpolated over land.duration, then held (with
//           the config's stance_landing, by stance control; with stand_after, then
//           standing up)
//
// The character (character/character.h) needs a planar root and joint groups with the
// roles hip, knee and ankle; any other groups (waist, shoulder, elbow, wrist, ...) are
// driven too. Groups of role neck hold 0 with the character's default gains and are not
// parameters; every other group has a target per phase.
//
// Targets. Each phase has a target pose Omega_i: one angle per parameterized group, left
// and right sharing it. Inside a phase the target moves linearly from the target commanded
// when the phase began (Omega_{i-1}, as joint angles) to Omega_i over the phase's known or
// predicted duration. In stance phases the feet, pelvis and upper torso track world-frame
// pitches (paper section 5): the hip group's value is the world pitch of the hips' parent
// link (the pelvis), the ankle group's the world pitch of the foot, and the topmost waist
// group's the world pitch of its child link (the chest); each is turned into a joint target
// every step from the current pose. In flight all targets are joint angles.
//
// Torques. Every joint is PD-controlled, tau = kp (target - q) - kd qdot; hips, knees and
// ankles use the phase's own gains, the other groups the character's default gains. In
// start, crouch and land a Jacobian-transpose balance controller adds joint torques
// tau = J^T F for a virtual force F on the centre of mass (Pratt et al. 2001): F_x servos
// the COM over the middle of the feet, F_z = M g supports the weight. J is the Jacobian of
// the COM position, taken as a point fixed to the upper body, with respect to the ankle,
// knee and hip of each leg when the feet are the base, so J^T F at joint j is
// -(c - p_j) x F (2D cross product, c the COM, p_j the joint position); each leg carries
// half of F. No external force is ever applied: the root is unactuated and all motion
// comes from joint torques, which the joint drive keeps within each joint's limit on the
// net torque (physics/drive.h).
//
// Landing controller (paper section 6, 2D only). During fall, while the pelvis is within
// 60 degrees of upright, the hip target places each ankle horizontally at
// x_c + landing.offset + landing.velocity_gain * v_x, where x_c is where the COM is
// predicted to cross the landing surface ballistically; the hip angle comes from the
// two-link leg geometry (hip-knee and knee-ankle distances of the standing model) with
// the knee at its phase target. With landing_at_touchdown, x_c is where the COM will be when
// it has come down to its standing height above the surface, less the soles' lead over the
// ankles, so the COM comes down over the middle of the soles (the paper's x_c, where the
// COM would reach the surface itself, overshoots, and the optimized offset that makes up
// for it holds only for the pitch the input motion lands with); with landing_reach the
// hips reach that goal within landing_reach seconds of the peak and then follow it.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "character/character.h"
#include "control/controller.h"
#include "control/parameters.h"
#include "control/stance_controller.h"
#include "physics/centroidal.h"
#include "physics/com_velocity.h"

namespace diverse {

enum JumpPhase : int { kStart = 0, kCrouch, kExtend, kRise, kFall, kLand, kNumJumpPhases };
const char* jump_phase_name(int phase);  // "start", "crouch", ...
// The phase gains every jump controller optimizes: PHASE.kp_hip, PHASE.kd_hip, ..., of
// hips, knees and ankles, appended to `specs` (shared by jump2d and jump3d).
void append_jump_gain_specs(int phase, std::vector<ParamSpec>& specs);
// The six phase names, in order, for PhaseTimes::names.
std::vector<std::string> jump_phase_names();

// Constants that are not optimized (documented defaults; the task file may override).
struct JumpControllerConfig : ControllerConfig {
  double balance_kp = 1500;          // N/m, horizontal COM servo
  double balance_kd = 300;           // N s/m
  double balance_max_force = 400;    // N, clamp on |F_x|
  // m; > 0: in the crouch the balance servo leads the COM along a lean instead of holding
  // it over the feet: its target moves from the feet (plus the balance offset) to this far
  // ahead of them over the crouch, at the speed that takes (F_x = kp (x_ref - x) +
  // kd (v_ref - v)), so a crouch that leans in to build a jump's forward speed follows the
  // same path after a push instead of falling from wherever the push left it; 0: held
  // over the feet (the paper's).
  double crouch_lean = 0;
  double gravity_compensation = 1;   // F_z = this * M g during balance
  bool landing_control = true;       // servo the feet during fall
  double landing_height_m = 0;       // m, height of the surface the COM prediction uses
  double extend_timeout = 0.8;       // s; an extend that never leaves the ground ends here
  double airborne_time = 0.01;       // s without contact (COM rising) that counts as take-off
  // s; > 0: the rise phase reaches its targets this long after take-off instead of at the
  // predicted peak (a quick tuck turns a backflip faster); 0 = over the whole rise.
  double tuck_time = 0;
  // s; > 0: the fall phase reaches its targets this long after the peak instead of at the
  // predicted touch-down (opening out of a tuck in time to land); 0 = over the whole fall.
  double open_time = 0;
  // rad; > 0: the rise phase (a tuck) lasts past the peak until the root has turned this
  // far since take-off, so a flip opens for its landing when it has come round, as a
  // gymnast opens when the floor comes into view; 0 = the fall phase begins at the peak.
  double open_rotation = 0;
  // rad; > 0: the rise phase (a tuck) lasts past the peak until the body as a whole,
  // opened now, would have turned this far in the air by touch-down, and no longer than
  // until touch-down is open_time away. The body's turn is its mean pitch rate (its angular
  // momentum about its COM over its inertia there, physics/centroidal.h) integrated from
  // take-off; the prediction adds what the momentum, constant in flight, turns it through
  // opening over open_time and then open (with the inertia it had at take-off) until the
  // COM is back at its take-off height. A flip that took off with less spin stays tucked
  // longer, one with more opens sooner, as a gymnast spots the landing. With open_rotation
  // as well, the root must also have turned that far since take-off.
  double open_turn = 0;
  // true: the land phase runs stance control (control/stance_controller.h), as the 3D
  // jumps' does: the J^T force on the COM held so that its centre of pressure stays inside
  // the soles, the pelvis's world pitch held by the stance legs, the feet tracking theirs, the chest
  // tracked with the waist; the land pose's pelvis, chest and foot values become those
  // links' world pitches, reached over land.duration from where they were at touch-down.
  // false: the paper's land phase (PD toward the land pose plus the J^T balance above).
  bool stance_landing = false;
  // s; >= 0 (with stance_landing): this long after the land phase has reached its pose,
  // stand up from it over stand_duration, to the tracked links level and every other joint
  // at the model's qpos0, instead of holding a deep landing crouch until it gives way;
  // < 0: hold the land pose.
  double stand_after = -1;
  double stand_duration = 0.5;  // s
  // true: the soles stay level in start, crouch and land (the feet track world pitch 0;
  // the pose's foot values of those phases are not parameters), so the character stands,
  // crouches and lands flat-footed instead of balancing on a heel or toe edge, its support
  // a point; the extend still pushes off from the toes. false: the paper's foot targets.
  bool level_feet = false;
  // s; > 0 (with landing_control): the hips reach the landing controller's goal this long
  // after the fall begins and then follow it, so the feet go where the COM will come down
  // whatever the pose at the peak; 0: the paper's, the goal reached over the whole fall.
  double landing_reach = 0;
  // true (with landing_control): the landing controller aims the ankles where the COM
  // will be at touch-down (when it has come down to its standing height above the landing
  // surface) less the sole's lead over the ankle, so landing.offset and velocity_gain are
  // corrections to a COM over the middle of the soles; false: the paper's, where the COM
  // would cross the landing surface itself.
  bool landing_at_touchdown = false;

  std::shared_ptr<const ControllerConfig> with_landing_height(double height) const override;
  double landing_height() const override { return landing_height_m; }
};

class JumpControllerType : public ControllerType {
 public:
  const char* name() const override { return "jump2d"; }
  const char* description() const override {
    return "phase-based jump of a planar character (start, crouch, extend, rise, fall, land)";
  }
  std::shared_ptr<const ControllerConfig> read_config(const TomlReader& r) const override;
  void check(const Character& body, const std::string& task_file) const override;
  std::vector<ParamSpec> parameter_specs(const Character& body,
                                         const ControllerConfig& config) const override;
  std::unique_ptr<Controller> make(const Character& body, const ControllerConfig& config,
                                   const std::vector<double>& values) const override;
};

class JumpController : public Controller {
 public:
  JumpController(const Character& body, const JumpControllerConfig& config);

  // The free parameters for `body`: per phase a target per parameterized group (but the
  // level feet, with `config.level_feet`) and kp, kd of hips, knees and ankles; then
  // durations and the landing and balance offsets (90 for the planar human, 87 with level
  // feet).
  static std::vector<ParamSpec> parameter_specs(const Character& body, const JumpControllerConfig& config);
  // Values in parameter_specs() order.
  void set_parameters(const std::vector<double>& values);

  void reset(const mjModel* m, const mjData* d) override;
  void control(const mjModel* m, mjData* d, const ContactState& contacts,
               JointDrive& drive) override;

  int phase() const override { return phase_; }
  bool phase_changed() const override { return phase_changed_; }
  const PhaseTimes& phase_times() const override { return times_; }
  bool gave_up() const override { return extend_timed_out_; }
  const std::array<double, 3>& com() const override { return com_; }
  const std::array<double, 3>& com_velocity() const override { return com_vel_; }
  // Joint targets (rad) commanded in the last step, one per Character::joints entry.
  const std::vector<double>& targets() const { return target_; }

 private:
  enum class Tracked { kNone, kParent, kChild };  // world-pitch tracking in stance
  void enter(int phase, double time);
  bool time_to_open(const CentroidalPitch& now) const;
  double parent_pitch(int j, const double* qpos) const;
  double to_local(int j, const double* qpos, double world) const;
  double to_world(int j, const double* qpos, double local) const;
  double landing_hip_goal(int j, const mjData* d) const;
  void enter_stance_landing(const mjData* d);
  void control_stance_landing(const mjModel* m, const mjData* d, JointDrive& drive, double s);

  const Character& body_;
  JumpControllerConfig config_;
  int hip_ = -1, knee_ = -1, ankle_ = -1, chest_ = -1;  // group indices
  std::vector<int> posed_;         // the parameterized groups, in parameter order
  std::vector<int> pose_slot_;     // per group: index into posed_, or -1 (holds 0)
  std::vector<int> gain_slot_;     // per group: 0 hip, 1 knee, 2 ankle, -1 default gains
  std::vector<Tracked> tracked_;   // per joint, in stance phases
  std::vector<DampedDof> damped_;  // scratch: a tracked joint's damped velocity
  std::vector<int> side_;          // per joint: 0 left or centre, 1 right
  double thigh_length_ = 0, shin_length_ = 0;  // m, hip-knee and knee-ankle at qpos0
  // Parameters unpacked.
  std::array<std::vector<double>, kNumJumpPhases> pose_{};  // per phase, per posed_ entry
  std::array<std::array<double, 3>, kNumJumpPhases> kp_{}, kd_{};  // hip, knee, ankle
  double start_duration_ = 0.2, crouch_duration_ = 0.4, land_duration_ = 0.3;
  double landing_offset_ = 0, landing_velocity_gain_ = 0, balance_offset_ = 0;

  int phase_ = kStart;
  bool phase_changed_ = false;
  bool extend_timed_out_ = false;
  double phase_begin_ = 0, phase_duration_ = 1;
  double takeoff_com_z_ = 0;
  double takeoff_pitch_ = 0;  // root pitch at take-off (rad, unwrapped)
  // open_turn: the body's inertia about its COM at take-off (kg m^2), its turn since
  // take-off (rad), when that was last brought up to date (s) and its spin in this step.
  double takeoff_inertia_ = 0, flight_turn_ = 0, spin_time_ = 0;
  CentroidalPitch spin_;
  CentroidalPitchOf centroidal_;  // of the character's subtree, set by reset()
  double free_since_ = -1;  // time contact was last lost during extend (s), -1 if touching
  PhaseTimes times_;
  // Per joint: target at the start of the phase (rad); in stance phases the world pitch
  // of the tracked link for the world-frame joints.
  std::vector<double> from_;
  bool from_is_world_ = false;
  const double* q_ = nullptr;   // qpos of the current step
  std::vector<double> target_;  // per joint: last commanded target (rad)
  std::vector<double> balance_; // per joint: J^T F of this step (Nm)
  std::array<double, 3> com_{}, com_vel_{};
  SubtreeComVelocity com_velocity_;  // of the character's subtree, set by reset()
  // stance_landing: the land phase's stance control, made by reset(), and the world
  // pitches (root, torso, feet) it moves from (at touch-down) and to (the land pose).
  std::unique_ptr<StanceController> stance_;
  std::array<double, 3> land_from_{}, land_goal_{};
  double gravity_ = 9.81;
  double standing_com_z_ = 0;  // m, the COM's height at reset()
  double sole_ahead_ = 0;      // m, the soles' middles ahead of the ankles at reset()
};

}  // namespace diverse
