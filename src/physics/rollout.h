// The rollout loop: control, observe, step, until the outcome is decided.
//
// Each step runs mj_step1 (kinematics, contacts and velocities of the current state),
// then the hooks' control() writes d->ctrl (and the worker's dof_damping; if it changed,
// the passive forces mj_step1 computed are recomputed with mj_passive), observe() decides
// whether to stop, and mj_step2 integrates. This computes exactly what mj_step does with
// the same inputs, so a recorded rollout replays bit for bit with plain mj_step (see
// replay()).
//
// With a JointDrive (physics/drive.h) the hooks' control() writes the drive's requests
// instead; the drive writes ctrl and dof_damping, and a step whose net joint torque would
// exceed a limit is integrated again from the same state with those joints' damping made
// explicit. Only the final integration's inputs are recorded, and they replay exactly.
//
// A rollout that goes unstable (a MuJoCo warning, a non-finite state, or a MuJoCo error
// caught by the guard) stops and reports it; it never throws or aborts.
#pragma once

#include <mujoco/mujoco.h>

#include <functional>
#include <string>
#include <vector>

#include "physics/drive.h"
#include "physics/model.h"

namespace diverse {

class StepHooks {
 public:
  virtual ~StepHooks() = default;
  // Called after mj_step1: writes d->ctrl and may write m->dof_damping, or, in a rollout
  // with a JointDrive, sets the drive's requests (the drive writes both).
  virtual void control(mjModel* m, mjData* d) = 0;
  // Called after control(), before integration. Return true to stop before this step.
  virtual bool observe(const mjModel* m, const mjData* d) = 0;
  // Called after each step is integrated (its last integration), with mjData as a plain
  // mj_step leaves it: the contacts and forces of the state before the step, the velocity
  // after it. Not called for a step that blew up. For measures that a replay of the record
  // would take the same way (task/foot_slip.h).
  virtual void stepped(const mjModel* m, const mjData* d) {
    (void)m, (void)d;
  }
};

// Everything needed to replay a rollout exactly, and what to check it with.
// Kept only when a StepRecorder is passed; off in the optimizer's hot path.
struct StepRecorder {
  int nq = 0, nu = 0, ndamp = 0;
  double timestep = 0;                // s
  std::vector<double> qpos0, qvel0;   // initial state
  std::vector<int> damped_dofs;       // dof indices whose damping the controller writes
  // Damping changes: before step `step`, dof_damping[damped_dofs[k]] = values[k].
  struct DampingChange {
    int step = 0;
    std::vector<double> values;
  };
  std::vector<DampingChange> damping;
  // Per step, row-major: ctrl (nu), resulting qpos (nq), actuator force of that step (nu)
  // and the joint damping force of that step for the damped dofs (ndamp),
  // -dof_damping * qvel at the END of the step (the Euler integrator's damping is
  // implicit, physics/drive.h), so motor plus damping gives the net joint torque.
  std::vector<double> ctrl, qpos, actuator_force, damping_force;
  int steps() const { return nu > 0 ? static_cast<int>(ctrl.size()) / nu : 0; }
};

struct RolloutStats {
  int steps = 0;           // integration steps taken
  double time = 0;         // simulated time at the end (s)
  // Control effort of a rollout with a JointDrive (0 without one), over every step taken,
  // from each driven joint's net torque tau (motor plus damping on the end-of-step
  // velocity, as the drive bounds it) and its end-of-step velocity qdot:
  double effort = 0;         // N^2 m^2 s: the time integral of sum_k tau_k^2
  double positive_work = 0;  // J: the time integral of sum_k max(0, tau_k qdot_k)
  bool unstable = false;   // stopped because the simulation blew up
  std::string instability; // what blew up
};

// Runs from the worker's current state (the caller resets it and sets the initial
// state) for at most max_steps. `damped_dofs` lists the dofs whose dof_damping the hooks
// may write (recorded on change). `recorder` may be null.
RolloutStats run_rollout(SimWorker& worker, StepHooks& hooks, int max_steps,
                         const std::vector<int>& damped_dofs, StepRecorder* recorder);

// The same with the joints driven through `drive`, whose requests the hooks set in
// control(): the net torque of every driven joint stays within its limit at every step
// (physics/drive.h). The recorder's damped dofs are drive.dofs().
RolloutStats run_rollout(SimWorker& worker, StepHooks& hooks, int max_steps, JointDrive& drive,
                         StepRecorder* recorder);

// Replays a record on `m` (a plain, freshly loaded model) with mj_step and returns the
// largest |qpos difference| from the recorded qpos over all steps. `m` is modified
// (dof_damping), so pass a private copy.
double replay(mjModel* m, const StepRecorder& record);

// Replays the record's first `steps` steps on `m` (its dof_damping is modified) with plain
// mj_step from d's reset state, calling after_step(step, d) after each mj_step: d then holds
// the contacts, constraint forces and kinematics of the state before the step and the
// velocity after it (the Euler step moved the positions with that velocity). Stops early
// when after_step returns false. Returns false if MuJoCo raised an error. For measures of
// a motion taken from its exact replay (task/foot_slip.h).
bool replay_each_step(mjModel* m, mjData* d, const StepRecorder& record, int steps,
                      const std::function<bool(int, const mjData*)>& after_step);

}  // namespace diverse
