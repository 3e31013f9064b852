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
// ctrl; motor plus damper can then exceed the limit (around impacts by up to 1.7 times).
// JointDrive applies the request so that, at every step, the torque the motor and the
// damper apply together stays within the limit (docs/characters.md, "Torque limits"):
// see apply() and check() below; run_rollout() (physics/rollout.h) does both.
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

namespace diverse {

struct DrivenJoint {
  int actuator = -1;   // a motor on the joint, gear 1, forcerange [-limit, limit]
  int dof = -1;        // the joint's dof address
  double limit = 0;    // Nm, limit on the net torque (motor plus damping)
};

class JointDrive {
 public:
  JointDrive() = default;
  explicit JointDrive(std::vector<DrivenJoint> joints);

  int size() const { return static_cast<int>(joints_.size()); }
  const std::vector<DrivenJoint>& joints() const { return joints_; }
  // The dofs whose dof_damping the drive writes (for the step recorder).
  const std::vector<int>& dofs() const { return dofs_; }

  // The request of this step for joint k: net torque u - kd * qdot (Nm), kd >= 0.
  void set(int k, double u, double kd) {
    u_[static_cast<size_t>(k)] = u;
    kd_[static_cast<size_t>(k)] = kd;
  }
  double u(int k) const { return u_[static_cast<size_t>(k)]; }
  double kd(int k) const { return kd_[static_cast<size_t>(k)]; }

  // Implementation state, owned by physics/rollout.cc.
  std::vector<DrivenJoint> joints_;
  std::vector<int> dofs_;
  std::vector<double> u_, kd_;
  std::vector<char> explicit_;  // per joint: damping applied explicitly in the motor
};

// The largest net-torque excess over all steps of a record, as a fraction of the limit:
// max over steps and driven joints of |motor + damper| / limit - 1 (<= 0 when every limit
// holds). The damper torque of a step is -dof_damping * qvel at the END of the step, as
// the Euler integrator applies it. Replays the record on `m` (a plain, freshly loaded
// model; modified) with mj_step. Declared here, defined in physics/rollout.cc.
struct StepRecorder;
struct NetTorqueCheck {
  double worst_excess = 0;     // max |net| / limit - 1
  int worst_step = -1, worst_joint = -1;
  int steps = 0, steps_over_1_percent = 0;
};
NetTorqueCheck check_net_torque(mjModel* m, const StepRecorder& record,
                                const std::vector<DrivenJoint>& joints);

}  // namespace diverse
