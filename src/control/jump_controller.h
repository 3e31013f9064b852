// Phase-based jump controller for the planar human (paper section 6, figure 4).
//
// A finite state machine over six phases:
//
//   start   stance, balance, ends after start.duration
//   crouch  stance, ends after crouch.duration
//   extend  stance, targets applied at once (no interpolation) to build momentum,
//           ends when the character is airborne (no contact with anything for
//           airborne_time, COM rising)
//   rise    flight, ends at peak height (COM vertical velocity <= 0); duration predicted
//           as v_z / g at take-off
//   fall    flight, ends at the first contact; duration predicted as the ballistic time
//           back to take-off height, sqrt(2 (z_peak - z_takeoff) / g); optional landing
//           controller (below)
//   land    stance, balance, targets interpolated over land.duration, then held
//
// Targets. Each phase has a target pose Omega_i for the 8 parameterized joint types
// (hip, knee, ankle, lower and upper waist, shoulder, elbow, wrist; neck and head hold 0).
// Left and right limbs share targets. Inside a phase the target moves linearly from the
// target commanded when the phase began (Omega_{i-1}, as joint angles) to Omega_i over the
// phase's known or predicted duration. In stance phases the feet, pelvis and upper torso
// track world-frame pitches (paper section 5): the phase's hip value is the pelvis world
// pitch, its ankle value the foot world pitch, its upper-waist value the chest world
// pitch; each is turned into a joint target every step from the current pose. In flight
// all targets are joint angles.
//
// Torques. Every joint is PD-controlled, tau = kp (target - q) - kd qdot; hips, knees and
// ankles use the phase's own gains, the other joints fixed gains. In start and land a
// Jacobian-transpose balance controller adds joint torques tau = J^T F for a virtual
// force F on the centre of mass (Pratt et al. 2001): F_x servos the COM over the middle
// of the feet, F_z = M g supports the weight. J is the Jacobian of the COM position,
// taken as a point fixed to the upper body, with respect to the ankle, knee and hip of
// each leg when the feet are the base, so J^T F at joint j is -(c - p_j) x F (2D cross
// product, c the COM, p_j the joint position); each leg carries half of F. The sum is
// clamped to the joint's torque limit. No external force is ever applied: the root is
// unactuated and all motion comes from these joint torques.
//
// Landing controller (paper section 6, 2D only). During fall, while the pelvis is within
// 60 degrees of upright, the hip target places each ankle horizontally at
// x_c + landing.offset + landing.velocity_gain * v_x, where x_c is where the COM is
// predicted to cross the landing surface ballistically; the hip angle comes from the
// two-link leg geometry with the knee at its phase target.
//
// Implementation: MuJoCo motors carry the torque and the joint's dof_damping carries kd,
// so the Euler integrator treats the damping implicitly; the controller writes
// ctrl = clamp(tau) + kd qdot so that motor plus damping equals the clamped torque.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <string>
#include <vector>

#include "character/planar_human.h"
#include "control/parameters.h"

namespace diverse {

enum JumpPhase : int { kStart = 0, kCrouch, kExtend, kRise, kFall, kLand, kNumJumpPhases };
const char* jump_phase_name(int phase);  // "start", "crouch", ...

// Contact between the character and the environment in the current state.
struct ContactState {
  bool any = false;                       // any body touches anything
  std::array<bool, 2> foot{false, false}; // left, right foot touches something
  bool non_foot = false;                  // a body other than the feet touches something
};
ContactState scan_contacts(const mjModel* m, const mjData* d, const PlanarHuman& body);

// Constants that are not optimized (documented defaults; the task file may override).
struct JumpControllerConfig {
  // Fixed PD gains (kp Nm/rad, kd Nm s/rad) of the joint types without per-phase gains.
  std::array<double, kNumJointTypes> kp{0, 0, 0, 800, 800, 150, 40, 15, 40, 30};
  std::array<double, kNumJointTypes> kd{0, 0, 0, 80, 80, 15, 4, 1.5, 4, 3};
  double balance_kp = 1500;          // N/m, horizontal COM servo
  double balance_kd = 300;           // N s/m
  double balance_max_force = 400;    // N, clamp on |F_x|
  double gravity_compensation = 1;   // F_z = this * M g during balance
  bool landing_control = true;       // servo the feet during fall
  double landing_height = 0;         // m, height of the surface the COM prediction uses
  double extend_timeout = 0.8;       // s; an extend that never leaves the ground ends here
  double airborne_time = 0.01;       // s without contact (COM rising) that counts as take-off
};

// Times at which phases began (s, simulation time); negative if never reached.
struct PhaseTimes {
  std::array<double, kNumJumpPhases> begin{-1, -1, -1, -1, -1, -1};
  double takeoff() const { return begin[kRise]; }
  double peak() const { return begin[kFall]; }
  double landing() const { return begin[kLand]; }
};

class JumpController {
 public:
  JumpController(const PlanarHuman& body, const JumpControllerConfig& config);

  // The free parameters, their ranges and units (90 of them; see the .cc for the list).
  static const std::vector<ParamSpec>& parameter_specs();

  // Values in parameter_specs() order.
  void set_parameters(const std::vector<double>& values);

  // Starts the state machine at `start` from the state in d (after mj_step1 or
  // mj_forward), and writes every controlled joint's damping into m.
  void reset(mjModel* m, const mjData* d);
  // One control step from the current state (after mj_step1): transitions, then
  // targets, then torques into d->ctrl and kd into m->dof_damping.
  void control(mjModel* m, mjData* d, const ContactState& contacts);

  int phase() const { return phase_; }
  bool phase_changed() const { return phase_changed_; }  // in the last control()
  const PhaseTimes& phase_times() const { return times_; }
  bool extend_timed_out() const { return extend_timed_out_; }
  // COM (m) and its velocity (m/s) seen by the last control() step.
  const std::array<double, 3>& com() const { return com_; }
  const std::array<double, 3>& com_velocity() const { return com_vel_; }
  const std::vector<int>& damped_dofs() const { return damped_dofs_; }
  // Joint targets (rad) commanded in the last step, one per joint of PlanarHuman.
  const std::vector<double>& targets() const { return target_; }

 private:
  void enter(int phase, double time, mjModel* m);
  double to_local(int type, int joint_index, const double* qpos, double world) const;
  double to_world(int type, int joint_index, const double* qpos, double local) const;
  double landing_hip_goal(int joint_index, const mjData* d) const;

  const PlanarHuman& body_;
  JumpControllerConfig config_;
  // Parameters unpacked: pose[phase][type], gains, durations.
  std::array<std::array<double, kNumJointTypes>, kNumJumpPhases> pose_{};
  std::array<std::array<double, 3>, kNumJumpPhases> kp_{}, kd_{};  // hip, knee, ankle
  double start_duration_ = 0.2, crouch_duration_ = 0.4, land_duration_ = 0.3;
  double landing_offset_ = 0, landing_velocity_gain_ = 0, balance_offset_ = 0;

  int phase_ = kStart;
  bool phase_changed_ = false;
  bool extend_timed_out_ = false;
  double phase_begin_ = 0, phase_duration_ = 1;
  double takeoff_com_z_ = 0;
  double free_since_ = -1;  // time contact was last lost during extend (s), -1 if touching
  PhaseTimes times_;
  // Per joint: target at the start of the phase (rad); in stance phases the world pitch
  // of the tracked link for the world-frame joints (hip, ankle, upper waist).
  std::vector<double> from_;
  bool from_is_world_ = false;
  const double* q_ = nullptr;   // qpos of the current step
  std::vector<double> target_;  // per joint: last commanded target (rad)
  std::vector<int> damped_dofs_;
  std::array<double, 3> com_{}, com_vel_{};
  double gravity_ = 9.81;
};

}  // namespace diverse
