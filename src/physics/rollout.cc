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

}  // namespace

RolloutStats run_rollout(SimWorker& worker, StepHooks& hooks, int max_steps,
                         const std::vector<int>& damped_dofs, StepRecorder* recorder) {
  mjModel* m = worker.model();
  mjData* d = worker.data();
  RolloutStats stats;
  if (recorder != nullptr) start_record(m, d, damped_dofs, recorder);
  std::string error;
  std::vector<double> last_damping;
  for (int dof : damped_dofs) last_damping.push_back(m->dof_damping[dof]);
  for (int step = 0; step < max_steps; ++step) {
    if (!guarded_step1(m, d, &error)) {
      stats.unstable = true;
      stats.instability = "MuJoCo error: " + error;
      break;
    }
    hooks.control(m, d);
    // mj_step1 computed the passive (damping) forces with the damping of the previous
    // step; the hooks may have changed it. Recompute them so that this step is exactly
    // what mj_step does with the new damping (and so replays bit for bit).
    if (damping_changed(m, damped_dofs, &last_damping)) mj_passive(m, d);
    if (hooks.observe(m, d)) break;
    if (recorder != nullptr) {
      record_damping(m, step, recorder);
      recorder->ctrl.insert(recorder->ctrl.end(), d->ctrl, d->ctrl + m->nu);
      for (int dof : damped_dofs) {
        recorder->damping_force.push_back(-m->dof_damping[dof] * d->qvel[dof]);
      }
    }
    if (!guarded_step2(m, d, &error)) {
      stats.unstable = true;
      stats.instability = "MuJoCo error: " + error;
      break;
    }
    ++stats.steps;
    if (recorder != nullptr) {
      recorder->qpos.insert(recorder->qpos.end(), d->qpos, d->qpos + m->nq);
      recorder->actuator_force.insert(recorder->actuator_force.end(), d->actuator_force,
                                      d->actuator_force + m->nu);
    }
    if (simulation_unstable(m, d, &stats.instability)) {
      stats.unstable = true;
      break;
    }
  }
  if (stats.unstable) {
    // A MuJoCo error leaves mjData half-updated; never reuse it as is.
    mj_resetData(m, d);
    if (recorder != nullptr) {
      // Keep only complete steps.
      const int n = stats.steps;
      recorder->ctrl.resize(static_cast<size_t>(n) * recorder->nu);
      recorder->damping_force.resize(static_cast<size_t>(n) * recorder->ndamp);
    }
  }
  stats.time = stats.steps * m->opt.timestep;
  return stats;
}

double replay(mjModel* m, const StepRecorder& record) {
  install_mujoco_handlers();
  mjData* d = mj_makeData(m);
  std::copy(record.qpos0.begin(), record.qpos0.end(), d->qpos);
  std::copy(record.qvel0.begin(), record.qvel0.end(), d->qvel);
  double max_diff = 0;
  size_t change = 0;
  const int steps = std::min(record.steps(), static_cast<int>(record.qpos.size()) /
                                                 std::max(1, record.nq));
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
    if (!guarded_step(m, d, &error)) {
      max_diff = std::numeric_limits<double>::infinity();
      break;
    }
    const double* expected = record.qpos.data() + static_cast<long>(step) * record.nq;
    for (int i = 0; i < record.nq; ++i) {
      const double diff = std::fabs(d->qpos[i] - expected[i]);
      if (!(diff <= max_diff)) max_diff = std::isnan(diff) ? INFINITY : diff;
    }
  }
  mj_deleteData(d);
  return max_diff;
}

}  // namespace diverse
