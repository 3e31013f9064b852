// What the joint drive (physics/drive.h) costs: a PD rollout of the planar human dropped
// from 0.4 m onto its feet (a landing impact, where integrations are redone) through
// run_rollout() with a JointDrive, the same PD applied the old way (ctrl = clamp(tau) +
// kd qdot with implicit dof_damping, no drive), and raw mj_step replaying the drive
// rollout's recorded inputs, i.e. the physics of exactly that motion; and the same PD
// under Damping::kConstrained (every joint's torque solved on the inertia the step's
// contacts leave) against raw mj_step replaying its own record. All run interleaved within
// each iteration and are timed by thread CPU time, so load from other processes on the
// machine shifts them alike. Counters: drive_per_raw, old_per_raw and constrained_per_raw
// are throughputs relative to raw mj_step (1 = no overhead), redone the fraction of steps
// integrated more than once.
//
//   diverse_bench --benchmark_filter=DriveOverhead
#include <benchmark/benchmark.h>

#include <time.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "physics/drive.h"
#include "physics/model.h"
#include "physics/rollout.h"

namespace diverse {
namespace {

const std::string kHuman = std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.xml";
constexpr int kSteps = 1000;  // 2 s: the fall, the landing and settling

double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// PD toward a slight crouch, kp = 4 L /rad and kd = 0.4 L s/rad for a joint of limit L.
struct Crouch {
  explicit Crouch(const mjModel* m) : joints(driven_joints(m)) {
    for (const DrivenJoint& j : joints) {
      const std::string name = mj_id2name(m, mjOBJ_JOINT, m->dof_jntid[j.dof]);
      double t = 0;
      if (name.rfind("hip", 0) == 0) t = 0.4;
      if (name.rfind("knee", 0) == 0) t = -0.8;
      if (name.rfind("ankle", 0) == 0) t = 0.4;
      qpos.push_back(m->jnt_qposadr[m->dof_jntid[j.dof]]);
      target.push_back(t);
      kp.push_back(4 * j.limit);
      kd.push_back(0.4 * j.limit);
      dofs.push_back(j.dof);
    }
  }
  std::vector<DrivenJoint> joints;
  std::vector<int> qpos, dofs;
  std::vector<double> target, kp, kd;
};

class DrivenCrouch : public StepHooks {
 public:
  DrivenCrouch(const Crouch& c, JointDrive* drive) : c_(c), drive_(drive) {}
  void control(mjModel*, mjData* d) override {
    for (size_t k = 0; k < c_.joints.size(); ++k)
      drive_->set(static_cast<int>(k), c_.kp[k] * (c_.target[k] - d->qpos[c_.qpos[k]]), c_.kd[k]);
  }
  bool observe(const mjModel*, const mjData*) override { return false; }

 private:
  const Crouch& c_;
  JointDrive* drive_;
};

class OldCrouch : public StepHooks {
 public:
  explicit OldCrouch(const Crouch& c) : c_(c) {}
  void control(mjModel* m, mjData* d) override {
    for (size_t k = 0; k < c_.joints.size(); ++k) {
      const DrivenJoint& j = c_.joints[k];
      const double qd = d->qvel[j.dof];
      const double tau = c_.kp[k] * (c_.target[k] - d->qpos[c_.qpos[k]]) - c_.kd[k] * qd;
      d->ctrl[j.actuator] = std::clamp(tau, -j.limit, j.limit) + c_.kd[k] * qd;
      m->dof_damping[j.dof] = c_.kd[k];
    }
  }
  bool observe(const mjModel*, const mjData*) override { return false; }

 private:
  const Crouch& c_;
};

void drop(SimWorker& w) {
  w.reset();
  const mjModel* m = w.model();
  w.data()->qpos[m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "rootz")]] = 0.4;
}

// Thread CPU seconds of raw mj_step replaying a record's inputs from the drop.
double raw_seconds(SimWorker& worker, const StepRecorder& record) {
  drop(worker);
  mjModel* m = worker.model();
  mjData* d = worker.data();
  const double t0 = thread_seconds();
  size_t change = 0;
  for (int k = 0; k < record.steps(); ++k) {
    while (change < record.damping.size() && record.damping[change].step == k) {
      for (int j = 0; j < record.ndamp; ++j)
        m->dof_damping[record.damped_dofs[static_cast<size_t>(j)]] = record.damping[change].values[static_cast<size_t>(j)];
      ++change;
    }
    std::copy_n(record.ctrl.begin() + static_cast<long>(k) * m->nu, m->nu, d->ctrl);
    mj_step(m, d);
  }
  const double seconds = thread_seconds() - t0;
  benchmark::DoNotOptimize(d->qpos[0]);
  return seconds;
}

void BM_DriveOverhead(benchmark::State& state) {
  auto model = SharedModel::from_file(kHuman);
  SimWorker worker(model);
  const Crouch crouch(model->get());
  JointDrive drive(crouch.joints);
  DrivenCrouch driven(crouch, &drive);
  OldCrouch old(crouch);
  StepRecorder record;
  drop(worker);
  run_rollout(worker, driven, kSteps, drive, &record);
  drive.reset_counts();

  JointDrive constrained(crouch.joints, SaturatedDrive::kExplicit, Damping::kConstrained);
  DrivenCrouch driven_constrained(crouch, &constrained);
  StepRecorder constrained_record;
  drop(worker);
  run_rollout(worker, driven_constrained, kSteps, constrained, &constrained_record);

  double t_drive = 0, t_old = 0, t_raw = 0, t_constrained = 0, t_raw_constrained = 0;
  long long steps = 0;
  for (auto _ : state) {
    drop(worker);
    double t0 = thread_seconds();
    const RolloutStats a = run_rollout(worker, driven, kSteps, drive, nullptr);
    t_drive += thread_seconds() - t0;

    drop(worker);
    t0 = thread_seconds();
    const RolloutStats b = run_rollout(worker, old, kSteps, crouch.dofs, nullptr);
    t_old += thread_seconds() - t0;

    t_raw += raw_seconds(worker, record);

    drop(worker);
    t0 = thread_seconds();
    const RolloutStats c = run_rollout(worker, driven_constrained, kSteps, constrained, nullptr);
    t_constrained += thread_seconds() - t0;
    t_raw_constrained += raw_seconds(worker, constrained_record);

    benchmark::DoNotOptimize(a.steps + b.steps + c.steps);
    steps += kSteps;
  }
  const double n = static_cast<double>(steps);
  state.counters["raw_steps_per_s"] = n / t_raw;
  state.counters["drive_steps_per_s"] = n / t_drive;
  state.counters["old_steps_per_s"] = n / t_old;
  state.counters["drive_per_raw"] = t_raw / t_drive;
  state.counters["old_per_raw"] = t_raw / t_old;
  state.counters["constrained_per_raw"] = t_raw_constrained / t_constrained;
  state.counters["redone"] = static_cast<double>(drive.counts().redone_steps) /
                             static_cast<double>(std::max(1L, drive.counts().steps));
}
BENCHMARK(BM_DriveOverhead)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace
}  // namespace diverse
