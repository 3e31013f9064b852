#include "physics/rollout.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "physics/mujoco_guard.h"

namespace diverse {
namespace {

void start_record(const mjModel* m, const mjData* d, const std::vector<int>& damped_dofs,
                  StepRecorder* r) {
  r->nq = m->nq;
  r->nu = m->nu;
  r->ndamp = static_cast<int>(damped_dofs.size());
  r->timestep = m->opt.timestep;
  r->qpos0.assign(d->qpos, d->qpos + m->nq);
  r->qvel0.assign(d->qvel, d->qvel + m->nv);
  r->damped_dofs = damped_dofs;
  r->damping.clear();
  r->ctrl.clear();
  r->qpos.clear();
  r->actuator_force.clear();
  r->damping_force.clear();
}

// Logs the damping values if they differ from the last logged ones.
void record_damping(const mjModel* m, int step, StepRecorder* r) {
  bool changed = r->damping.empty();
  if (!changed) {
    const auto& last = r->damping.back().values;
    for (int k = 0; k < r->ndamp; ++k) {
      if (last[k] != m->dof_damping[r->damped_dofs[k]]) {
        changed = true;
        break;
      }
    }
  }
  if (!changed) return;
  StepRecorder::DampingChange change;
  change.step = step;
  change.values.resize(r->ndamp);
  for (int k = 0; k < r->ndamp; ++k) change.values[k] = m->dof_damping[r->damped_dofs[k]];
  r->damping.push_back(std::move(change));
}

// True if any damped dof's damping differs from `last`, which is then updated.
bool damping_changed(const mjModel* m, const std::vector<int>& dofs, std::vector<double>* last) {
  bool changed = false;
  for (size_t k = 0; k < dofs.size(); ++k) {
    const double v = m->dof_damping[dofs[k]];
    if (v != (*last)[k]) {
      (*last)[k] = v;
      changed = true;
    }
  }
  return changed;
}

// Everything mj_step2 changes that the step's own computation reads: the state it
// integrates (qpos, qvel, act, time) and the constraint solver's warm start
// (qacc_warmstart, read by mj_fwdConstraint). The rest of mjData that mj_step2 reads was
// computed by mj_step1 from the state alone and is left untouched by mj_step2, so after
// restore() a second mj_step2 computes exactly what mj_step computes from this state
// (checked bit for bit by tests/physics/drive_test.cc).
class PreStep2 {
 public:
  explicit PreStep2(const mjModel* m)
      : qpos_(static_cast<size_t>(m->nq)), qvel_(static_cast<size_t>(m->nv)),
        act_(static_cast<size_t>(m->na)), warmstart_(static_cast<size_t>(m->nv)) {}
  void save(const mjModel* m, const mjData* d) {
    mju_copy(qpos_.data(), d->qpos, m->nq);
    mju_copy(qvel_.data(), d->qvel, m->nv);
    mju_copy(act_.data(), d->act, m->na);
    mju_copy(warmstart_.data(), d->qacc_warmstart, m->nv);
    time_ = d->time;
  }
  void restore(const mjModel* m, mjData* d) const {
    mju_copy(d->qpos, qpos_.data(), m->nq);
    mju_copy(d->qvel, qvel_.data(), m->nv);
    mju_copy(d->act, act_.data(), m->na);
    mju_copy(d->qacc_warmstart, warmstart_.data(), m->nv);
    d->time = time_;
  }

 private:
  std::vector<mjtNum> qpos_, qvel_, act_, warmstart_;
  mjtNum time_ = 0;
};

// At most this many integrations per step. The last one has every driven joint explicit,
// whose net torque is the motor's alone and so within its forcerange: it always holds.
constexpr int kMaxPasses = 4;

void record_step(const mjModel* m, const mjData* d, const std::vector<int>& damped_dofs,
                 int step, StepRecorder* r) {
  record_damping(m, step, r);
  r->ctrl.insert(r->ctrl.end(), d->ctrl, d->ctrl + m->nu);
  r->qpos.insert(r->qpos.end(), d->qpos, d->qpos + m->nq);
  r->actuator_force.insert(r->actuator_force.end(), d->actuator_force, d->actuator_force + m->nu);
  // The Euler integrator applies the damper on the end-of-step velocity (physics/drive.h).
  for (int dof : damped_dofs) r->damping_force.push_back(-m->dof_damping[dof] * d->qvel[dof]);
}

// One step's share of the rollout's effort and positive work (RolloutStats).
void add_effort(const mjModel* m, const mjData* d, const JointDrive& drive, RolloutStats* stats) {
  const double h = m->opt.timestep;
  double squared = 0, power = 0;
  for (const DrivenJoint& j : drive.joints()) {
    const double qdot = d->qvel[j.dof];
    const double net = d->actuator_force[j.actuator] - m->dof_damping[j.dof] * qdot;
    squared += net * net;
    power += std::max(0.0, net * qdot);
  }
  stats->effort += h * squared;
  stats->positive_work += h * power;
}

// The loop of both run_rollout() overloads: `drive` null means the hooks write ctrl and
// dof_damping of `damped_dofs` themselves.
RolloutStats rollout(SimWorker& worker, StepHooks& hooks, int max_steps,
                     const std::vector<int>& damped_dofs, JointDrive* drive,
                     StepRecorder* recorder) {
  mjModel* m = worker.model();
  mjData* d = worker.data();
  RolloutStats stats;
  if (recorder != nullptr) start_record(m, d, damped_dofs, recorder);
  std::string error;
  std::vector<double> last_damping;
  for (int dof : damped_dofs) last_damping.push_back(m->dof_damping[dof]);
  PreStep2 pre_step2(m);
  for (int step = 0; step < max_steps; ++step) {
    if (!guarded_step1(m, d, &error)) {
      stats.unstable = true;
      stats.instability = "MuJoCo error: " + error;
      break;
    }
    hooks.control(m, d);
    // mj_step1 computed the passive (damping) forces with the damping of the previous
    // step; this step's may differ. Recompute them so that this step is exactly what
    // mj_step does with the new damping (and so replays bit for bit).
    const bool changed =
        drive != nullptr ? drive->apply(m, d) : damping_changed(m, damped_dofs, &last_damping);
    if (changed) mj_passive(m, d);
    if (hooks.observe(m, d)) break;
    if (drive != nullptr) pre_step2.save(m, d);
    bool integrated = guarded_step2(m, d, &error);
    // A driven joint whose implicit damper took its net torque past the limit: integrate
    // again from the same state with that joint's damping explicit (physics/drive.h).
    for (int pass = 1; integrated && drive != nullptr && pass < kMaxPasses; ++pass) {
      if (drive->check(m, d, pass + 1 == kMaxPasses)) break;
      pre_step2.restore(m, d);
      mj_passive(m, d);
      integrated = guarded_step2(m, d, &error);
    }
    if (!integrated) {
      stats.unstable = true;
      stats.instability = "MuJoCo error: " + error;
      break;
    }
    ++stats.steps;
    if (drive != nullptr) add_effort(m, d, *drive, &stats);
    if (recorder != nullptr) record_step(m, d, damped_dofs, step, recorder);
    if (simulation_unstable(m, d, &stats.instability)) {
      stats.unstable = true;
      break;
    }
    hooks.stepped(m, d);
  }
  // A MuJoCo error leaves mjData half-updated; never reuse it as is.
  if (stats.unstable) mj_resetData(m, d);
  stats.time = stats.steps * m->opt.timestep;
  return stats;
}

// Replays the first `steps` steps of a record on `m` with mj_step, calling
// after_step(step, d) after each. Returns false if MuJoCo raised an error.
template <class AfterStep>
bool replay_steps(mjModel* m, mjData* d, const StepRecorder& record, int steps,
                  AfterStep&& after_step) {
  std::copy(record.qpos0.begin(), record.qpos0.end(), d->qpos);
  std::copy(record.qvel0.begin(), record.qvel0.end(), d->qvel);
  size_t change = 0;
  std::string error;
  for (int step = 0; step < steps; ++step) {
    while (change < record.damping.size() && record.damping[change].step == step) {
      for (int k = 0; k < record.ndamp; ++k) {
        m->dof_damping[record.damped_dofs[k]] = record.damping[change].values[k];
      }
      ++change;
    }
    std::copy(record.ctrl.begin() + static_cast<long>(step) * record.nu,
              record.ctrl.begin() + static_cast<long>(step + 1) * record.nu, d->ctrl);
    if (!guarded_step(m, d, &error)) return false;
    if (!after_step(step, d)) return true;
  }
  return true;
}

}  // namespace

RolloutStats run_rollout(SimWorker& worker, StepHooks& hooks, int max_steps,
                         const std::vector<int>& damped_dofs, StepRecorder* recorder) {
  return rollout(worker, hooks, max_steps, damped_dofs, nullptr, recorder);
}

RolloutStats run_rollout(SimWorker& worker, StepHooks& hooks, int max_steps, JointDrive& drive,
                         StepRecorder* recorder) {
  return rollout(worker, hooks, max_steps, drive.dofs(), &drive, recorder);
}

bool replay_each_step(mjModel* m, mjData* d, const StepRecorder& record, int steps,
                      const std::function<bool(int, const mjData*)>& after_step) {
  install_mujoco_handlers();
  return replay_steps(m, d, record, steps, after_step);
}

double replay(mjModel* m, const StepRecorder& record) {
  install_mujoco_handlers();
  mjData* d = mj_makeData(m);
  double max_diff = 0;
  const int steps = std::min(record.steps(), static_cast<int>(record.qpos.size()) /
                                                 std::max(1, record.nq));
  const bool ok = replay_steps(m, d, record, steps, [&](int step, const mjData* data) {
    const double* expected = record.qpos.data() + static_cast<long>(step) * record.nq;
    for (int i = 0; i < record.nq; ++i) {
      const double diff = std::fabs(data->qpos[i] - expected[i]);
      if (!(diff <= max_diff)) max_diff = std::isnan(diff) ? INFINITY : diff;
    }
    return true;
  });
  if (!ok) max_diff = std::numeric_limits<double>::infinity();
  mj_deleteData(d);
  return max_diff;
}

NetTorqueCheck check_net_torque(mjModel* m, const StepRecorder& record,
                                const std::vector<DrivenJoint>& joints) {
  install_mujoco_handlers();
  mjData* d = mj_makeData(m);
  NetTorqueCheck check;
  check.worst_excess = -std::numeric_limits<double>::infinity();
  std::string why;
  const bool ok = replay_steps(m, d, record, record.steps(), [&](int step, const mjData* data) {
    if (simulation_unstable(m, data, &why)) {
      check.blew_up = true;
      return false;
    }
    ++check.steps;
    bool over = false;
    for (size_t k = 0; k < joints.size(); ++k) {
      const DrivenJoint& j = joints[k];
      // Motor plus the damper on the end-of-step velocity: the torque the Euler step
      // applied (physics/drive.h). The same expression as JointDrive::check().
      const double net = data->actuator_force[j.actuator] - m->dof_damping[j.dof] * data->qvel[j.dof];
      const double excess = std::fabs(net) / j.limit - 1;
      if (excess > check.worst_excess) {
        check.worst_excess = excess;
        check.worst_torque = net;
        check.worst_step = step;
        check.worst_joint = static_cast<int>(k);
      }
      if (excess > 0.01) over = true;
    }
    if (over) ++check.steps_over_1_percent;
    return true;
  });
  if (!ok) check.blew_up = true;
  if (check.blew_up) check.worst_excess = std::numeric_limits<double>::infinity();
  if (check.worst_step < 0 && !check.blew_up) check.worst_excess = 0;
  mj_deleteData(d);
  return check;
}

}  // namespace diverse
