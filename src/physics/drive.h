// Joint drives: PD torques whose net torque stays within each joint's limit.
//
// A controller asks, per driven joint k and per step, for the net joint torque
//
//     tau_k = u_k - kd_k * qdot_k          clamped to [-limit_k, limit_k]
//
// where u_k is everything but the damping (kp (target - q), balance torques, ...). The
// damping part is best integrated implicitly (MuJoCo's Euler integrator treats
// dof_damping implicitly, so large kd stays stable at a 2 ms step), but an implicit damper
// acts on the END-of-step velocity, which the controller does not know when it writes
// ctrl. The Euler step solves (M + h D) qacc = f - D qvel_t and sets
// qvel_{t+1} = qvel_t + h qacc, so M qacc = f - D qvel_{t+1}: the damper torque of the
// step is -dof_damping * qvel_{t+1} (MuJoCo 2.2.2 documentation, "Computation",
// "Numerical integration"). When an impact changes qvel within the step, motor plus
// damper can exceed the limit (by up to 1.7 times around landings).
//
// The torque limit holds on the net torque (SPEC section 8), so each step is applied in
// one of two ways per joint, chosen from the state at the step's start:
//
//  - implicit: dof_damping = kd, ctrl = u. Used when |u| <= limit and the request is not
//    saturated, |u - kd qdot_t| <= limit. The net torque is u - kd qdot_{t+1}.
//  - explicit: dof_damping = 0, ctrl = clamp(u - kd qdot_t). The net torque is ctrl, within
//    the limit by construction (the motor's forcerange is the limit).
//
// Explicit damping is unstable once kd h / I > 2 (h the step, I the joint's effective
// inertia): at a jump's flight gains a joint swinging hard towards its target, its request
// at the limit or its spring part beyond it, overshoots, its next request is at the limit
// the other way, and the net torque alternates step by step between +limit and -limit (the
// backflip's hips in the air at 2 ms; two motions 1e-6 apart part by 1e-2 within 0.1 s).
// SaturatedDrive::kStablePd applies such a joint's request with its damper on the
// predicted end-of-step velocity, as stable PD control does (Tan, Liu and Turk 2011):
//
//     ctrl = clamp((u - kd qdot_t) / (1 + h kd / I)),    I = 1 / (M^-1)_kk
//
// (I from the factorized mass matrix: the joint's inertia with every other joint and the
// root free; contacts only make it larger). For a joint alone this is the implicit
// solution u - kd qdot_{t+1}; its damping gain kd / (1 + h kd / I) is stable for any kd.
// The net torque is still ctrl, within the limit. SaturatedDrive::kExplicit (the default)
// is the plain clamp above, with which every input motion of the first release was found.
//
// Damping::kConstrained drives every joint this way, but with the inertia the joints have
// while this step's contacts and limits hold: the controller's requests are solved
// together, each damper on the velocity the drive predicts for the step's end,
//
//     tau = u - Kd (c qdot_t + h B tau),   B = C M_c^-1 S^T,
//     M_c^-1 = M^-1 - M^-1 J^T (J M^-1 J^T + R)^-1 J M^-1
//
// (S selects the driven joints, C the velocities the dampers act on: a joint's own, or a
// link's world pitch rate for a controller that damps that; J and R the step's
// constraint rows and their regularization, from mj_step1). Solved as one nv x nv system,
// (M + J^T R^-1 J + h S^T Kd C) x = S^T (u - Kd c qdot_t), tau = u - Kd (c qdot_t + h C x),
// factorized once a step. A joint whose torque would pass its limit is held at the limit
// and the rest solved again, the furthest beyond its limit first (a rank-one update of
// the factorized system per held joint). Every joint is then applied explicitly, ctrl = tau, dof_damping 0: the net
// torque is ctrl, within the limit, and a record replays as any other.
//
// Why: MuJoCo's implicit damping and the stable PD above divide a joint's damper by
// 1 + h kd / I with I the joint's inertia with every other joint and the root free. In a
// push-off the feet are held by the floor and the inertia a hip meets is the trunk's, not
// the leg's; with the free inertia the damper is weakened by a factor that changes with
// the step (the backflip's hips in its push-off: divided by 3.5 at 2 ms, 2.3 at 1 ms), and
// the same motion jumps differently at each step. With the constrained inertia the factor is
// near 1 where the contacts hold the joint and as before where nothing does, so a motion
// converges as the step shrinks (docs/notes/2026-12-05-drive-that-converges.md).
//
// An implicit joint can still exceed its limit if qdot_{t+1} jumps (an impact within the
// step). run_rollout() (physics/rollout.h) therefore integrates, checks every implicit
// joint's net torque on qdot_{t+1}, and if one exceeds its limit restores the state from
// before the integration and integrates again with the violating joints explicit
// (apply() and check() below). Everything mj_step1 computed depends only on the restored
// state, so the step taken is exactly what plain mj_step computes from that state with the
// final ctrl and dof_damping; the recorder logs those, and a replay repeats them bit for
// bit.
#pragma once

#include <mujoco/mujoco.h>

#include <Eigen/Dense>
#include <vector>

namespace diverse {

struct DrivenJoint {
  int actuator = -1;   // a motor on the joint, gear 1, forcerange [-limit, limit]
  int dof = -1;        // the joint's dof address
  double limit = 0;    // Nm (N on a slide joint), limit on the net torque (motor plus damping)
};

// The driven joints of a model, derived from its actuators alone, so that a saved model
// suffices to check a motion: each actuator that is a plain motor (no dynamics, fixed
// gain 1, no bias) on a hinge or slide joint with gear 1, forcelimited with a symmetric
// forcerange [-L, L], L > 0, on a joint no other actuator acts on. In actuator order.
std::vector<DrivenJoint> driven_joints(const mjModel* m);

// How an explicit joint's damping is applied (above): on qdot_t, or on the predicted
// end-of-step velocity (a task's `[simulation] saturated_drive`, "explicit" or "stable_pd").
enum class SaturatedDrive { kExplicit, kStablePd };

// How the dampers are integrated (above): by MuJoCo on each joint's own inertia, saturated
// joints as SaturatedDrive says (kMujoco, the default), or all joints together on the
// inertia with the step's contacts held (kConstrained; a task's `[simulation] damping`).
enum class Damping { kMujoco, kConstrained };

// A term of the velocity a damper acts on under Damping::kConstrained: weight * qvel[dof].
struct DampedDof {
  int dof = -1;
  double weight = 0;
};

class JointDrive {
 public:
  JointDrive() = default;
  explicit JointDrive(std::vector<DrivenJoint> joints,
                      SaturatedDrive saturated = SaturatedDrive::kExplicit,
                      Damping damping = Damping::kMujoco);

  int size() const { return static_cast<int>(joints_.size()); }
  const std::vector<DrivenJoint>& joints() const { return joints_; }
  // The dofs whose dof_damping the drive writes (for the step recorder), joint order.
  const std::vector<int>& dofs() const { return dofs_; }

  // The request of this step for joint k: net torque u - kd * qdot (Nm), kd >= 0
  // (Nm s/rad). A request stands until the next set() of the same joint.
  void set(int k, double u, double kd) {
    u_[static_cast<size_t>(k)] = u;
    kd_[static_cast<size_t>(k)] = kd;
    damped_[static_cast<size_t>(k)].clear();
  }
  // The same with the damper on sum_i weight_i * qvel[dof_i] instead of the joint's own
  // velocity (a link's world pitch rate, say), under Damping::kConstrained. Under kMujoco
  // the controller adds such damping to u itself (it is then explicit).
  void set(int k, double u, double kd, const std::vector<DampedDof>& velocity) {
    u_[static_cast<size_t>(k)] = u;
    kd_[static_cast<size_t>(k)] = kd;
    damped_[static_cast<size_t>(k)] = velocity;
  }
  Damping damping() const { return damping_; }
  double u(int k) const { return u_[static_cast<size_t>(k)]; }
  double kd(int k) const { return kd_[static_cast<size_t>(k)]; }
  // How the last step applied joint k's damping: in the motor (dof_damping 0) or not.
  bool explicit_damping(int k) const { return explicit_[static_cast<size_t>(k)] != 0; }

  // How often steps were integrated again, since construction or reset_counts().
  struct Counts {
    long steps = 0;               // steps applied
    long redone_steps = 0;        // steps integrated more than once
    long redos = 0;               // extra integrations in all
    long all_explicit_steps = 0;  // steps that fell back to every joint explicit
  };
  const Counts& counts() const { return counts_; }
  void reset_counts() { counts_ = Counts{}; }

  // The step protocol, in this order, between mj_step1 and the end of the step
  // (run_rollout() follows it; tests may too):
  //
  // apply(): chooses each joint's way from the request and qdot_t (d->qvel after mj_step1)
  // and writes d->ctrl and m->dof_damping. Returns true if any dof_damping changed: the
  // passive forces mj_step1 computed are then stale and need mj_passive.
  bool apply(mjModel* m, mjData* d);
  // check(), after mj_step2: true if every implicit joint's net torque, motor force minus
  // kd qdot_{t+1}, is within its limit (exactly, no tolerance), or if none is implicit.
  // Otherwise switches the violating joints to explicit (every joint if `all_explicit`),
  // rewrites d->ctrl and m->dof_damping and returns false: the caller restores the state
  // from before mj_step2, calls mj_passive and mj_step2 again, and checks again.
  bool check(mjModel* m, mjData* d, bool all_explicit);

 private:
  void make_explicit(mjModel* m, mjData* d, size_t k);

  // Damping::kConstrained: every joint's torque of this step into torque_.
  void solve_constrained(const mjModel* m, mjData* d);
  // The explicit torque of joint k from its request, qdot and (for kStablePd) the state.
  double explicit_torque(const mjModel* m, mjData* d, size_t k, double qdot);

  std::vector<DrivenJoint> joints_;
  SaturatedDrive saturated_ = SaturatedDrive::kExplicit;
  Damping damping_ = Damping::kMujoco;
  std::vector<int> dofs_;
  std::vector<mjtNum> unit_, response_;  // kStablePd scratch: e_k and M^-1 e_k
  std::vector<double> u_, kd_;
  std::vector<std::vector<DampedDof>> damped_;  // per joint: its damped velocity; empty = its own
  // Damping::kConstrained: this step's torques, and scratch kept between steps.
  std::vector<double> torque_;
  std::vector<mjtNum> row_, basis_;  // a constraint row, e_i
  std::vector<int> nonzero_;
  Eigen::MatrixXd inertia_, system_;  // H, and A = H + h S^T Kd C
  Eigen::LLT<Eigen::MatrixXd> system_llt_;
  Eigen::PartialPivLU<Eigen::MatrixXd> system_lu_;
  Eigen::VectorXd rhs_, step_rhs_;           // r (per joint), S^T r
  Eigen::VectorXd free_change_, change_;     // x with every joint free, x with W held
  Eigen::VectorXd unit_rhs_, projected_, weights_;  // s_w; V^T y; capacitance^-1 V^T y
  Eigen::MatrixXd held_response_, capacitance_;     // [P_w]; I - V^T Z
  Eigen::PartialPivLU<Eigen::MatrixXd> capacitance_lu_;
  std::vector<int> held_;                    // W: the joints held at their limit, in order
  // c_k . v: joint k's damped velocity in the velocities v.
  template <typename Vector>
  double damped_velocity(size_t k, const Vector& v) const;
  std::vector<double> qdot_;    // per joint: qdot_t of the current step (rad/s)
  std::vector<char> explicit_;  // per joint: damping applied explicitly in the motor
  bool redone_ = false;         // the current step has been integrated again
  Counts counts_;
};

// The largest net-torque excess over all steps of a record, as a fraction of the limit:
// max over steps and driven joints of |motor + damper| / limit - 1 (<= 0 when every limit
// holds), where the motor torque is the actuator force and the damper torque is
// -dof_damping * qvel at the END of the step, as the Euler integrator applies it. Replays
// the record on `m` (a plain, freshly loaded model; its dof_damping is modified) with
// mj_step; needs only the record's ctrl, damping and initial state. Defined in
// physics/rollout.cc beside replay().
struct StepRecorder;
struct NetTorqueCheck {
  double worst_excess = 0;     // max |net| / limit - 1 over steps and joints
  double worst_torque = 0;     // the net torque there (Nm)
  int worst_step = -1, worst_joint = -1;  // index into the record's steps and `joints`
  int steps = 0;               // steps replayed
  int steps_over_1_percent = 0;  // steps where some joint exceeds its limit by > 1 %
  bool blew_up = false;        // the replay hit a MuJoCo error or a non-finite state
};
NetTorqueCheck check_net_torque(mjModel* m, const StepRecorder& record,
                                const std::vector<DrivenJoint>& joints);

}  // namespace diverse
