#include "eval/throughput.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/rng.h"
#include "core/thread_pool.h"
#include "character/character.h"
#include "control/controller.h"
#include "control/stance_controller.h"
#include "core/error.h"
#include "physics/model.h"
#include "physics/rollout.h"

namespace diverse {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Replays a record's inputs with plain mj_step `repeats` times; returns steps per second.
double raw_step_rate(const mjModel* shared, const StepRecorder& record, double budget) {
  mjModel* m = mj_copyModel(nullptr, shared);
  mjData* d = mj_makeData(m);
  long long steps = 0;
  const auto start = Clock::now();
  do {
    mj_resetData(m, d);
    std::copy(record.qpos0.begin(), record.qpos0.end(), d->qpos);
    std::copy(record.qvel0.begin(), record.qvel0.end(), d->qvel);
    std::size_t change = 0;
    for (int k = 0; k < record.steps(); ++k) {
      while (change < record.damping.size() && record.damping[change].step == k) {
        for (int j = 0; j < record.ndamp; ++j)
          m->dof_damping[record.damped_dofs[static_cast<std::size_t>(j)]] = record.damping[change].values[static_cast<std::size_t>(j)];
        ++change;
      }
      std::copy(record.ctrl.begin() + static_cast<long>(k) * record.nu,
                record.ctrl.begin() + static_cast<long>(k + 1) * record.nu, d->ctrl);
      mj_step(m, d);
    }
    steps += record.steps();
  } while (seconds_since(start) < budget);
  const double rate = static_cast<double>(steps) / seconds_since(start);
  mj_deleteData(d);
  mj_deleteModel(m);
  return rate;
}

}  // namespace

nlohmann::json ThroughputReport::to_json() const {
  return {{"raw_mj_step_steps_per_second", raw_steps_per_second},
          {"rollout_steps_per_second", rollout_steps_per_second},
          {"rollout_over_raw", rollout_ratio},
          {"steps_per_rollout", rollout_steps},
          {"rollouts_per_second_1_thread", rollouts_per_second_1},
          {"rollouts_per_second_n_threads", rollouts_per_second_n},
          {"threads", threads},
          {"parallel_speedup", speedup}};
}

ThroughputReport measure_throughput(const TaskEvaluator& evaluator, const ParameterSet& m0,
                                    const ThroughputOptions& options) {
  ThroughputReport report;
  auto worker = evaluator.make_worker();

  // M0's inputs, recorded once.
  StepRecorder record;
  EvaluationOptions recording;
  recording.recorder = &record;
  evaluator.evaluate(m0.values(), *worker, recording);
  report.rollout_steps = record.steps();

  // Interleave raw and rollout measurements so both see the same machine conditions.
  double raw = 0, rollout = 0;
  for (int round = 0; round < 2; ++round) {
    raw += raw_step_rate(evaluator.model().get(), record, options.seconds / 2);
    long long steps = 0;
    const auto start = Clock::now();
    do {
      const Evaluation e = evaluator.evaluate(m0.values(), *worker);
      steps += e.stats.steps;
    } while (seconds_since(start) < options.seconds / 2);
    rollout += static_cast<double>(steps) / seconds_since(start);
  }
  report.raw_steps_per_second = raw / 2;
  report.rollout_steps_per_second = rollout / 2;
  report.rollout_ratio = report.rollout_steps_per_second / report.raw_steps_per_second;

  // Parallel speed-up on a batch of perturbed samples, as a generation of the optimizer.
  report.threads = options.threads > 0 ? options.threads : ThreadPool::hardware_threads();
  const Eigen::VectorXd x0 = m0.normalized();
  std::vector<Eigen::VectorXd> batch;
  Rng rng(derive_seed(1, {42}));
  for (int i = 0; i < options.batch; ++i) {
    Eigen::VectorXd x = x0;
    for (Eigen::Index j = 0; j < x.size(); ++j)
      x[j] = std::clamp(x[j] + 0.03 * rng.normal(), 0.0, 1.0);
    batch.push_back(std::move(x));
  }
  auto batch_rate = [&](int threads) {
    ThreadPool pool(threads);
    std::vector<std::unique_ptr<SimWorker>> workers;
    for (int w = 0; w < pool.size(); ++w) workers.push_back(evaluator.make_worker());
    long long rollouts = 0;
    const auto start = Clock::now();
    do {
      pool.parallel_for(batch.size(), [&](std::size_t i, int w) {
        evaluator.evaluate_normalized(batch[i], *workers[static_cast<std::size_t>(w)]);
      });
      rollouts += static_cast<long long>(batch.size());
    } while (seconds_since(start) < options.seconds);
    return static_cast<double>(rollouts) / seconds_since(start);
  };
  report.rollouts_per_second_1 = batch_rate(1);
  report.rollouts_per_second_n = batch_rate(report.threads);
  report.speedup = report.rollouts_per_second_n / report.rollouts_per_second_1;
  return report;
}

namespace {

class StandHooks : public StepHooks {
 public:
  StandHooks(StanceController& stance, JointDrive& drive) : stance_(stance), drive_(drive) {}
  void control(mjModel* m, mjData* d) override {
    if (first_) stance_.reset(m, d);
    first_ = false;
    stance_.control(m, d, drive_);
  }
  bool observe(const mjModel*, const mjData*) override { return false; }

 private:
  StanceController& stance_;
  JointDrive& drive_;
  bool first_ = true;
};

}  // namespace

ThroughputReport measure_stance_throughput(const std::string& character_file,
                                           const ThroughputOptions& options, double standing_seconds) {
  const auto spec = std::make_shared<const CharacterSpec>(load_character_file(resolve_character_file(character_file)));
  if (spec->root != RootKind::kFree) {
    throw UserError(spec->file + ": root.kind: expected a free root for stance control (planar characters are "
                                 "measured on a task: diverse bench TASK)");
  }
  const auto model = SharedModel::from_file(spec->model);
  const Character body = bind_character(spec, model->get(), spec->model);
  SimWorker worker(model);
  const int steps = static_cast<int>(std::ceil(standing_seconds / model->get()->opt.timestep));
  StanceController stance(body, model->get());
  const std::vector<double> pose = stance.standing_pose(model->get());
  auto stand = [&](StepRecorder* recorder) {
    worker.reset();
    std::copy(pose.begin(), pose.end(), worker.data()->qpos);
    JointDrive drive = make_drive(body);
    StanceController controller(body, model->get());
    StandHooks hooks(controller, drive);
    return run_rollout(worker, hooks, steps, drive, recorder);
  };

  ThroughputReport report;
  StepRecorder record;
  stand(&record);
  report.rollout_steps = record.steps();
  double raw = 0, rollout = 0;
  long long rollouts = 0;
  double rollout_time = 0;
  for (int round = 0; round < 2; ++round) {
    raw += raw_step_rate(model->get(), record, options.seconds / 2);
    long long n = 0;
    const auto start = Clock::now();
    do {
      n += stand(nullptr).steps;
      ++rollouts;
    } while (seconds_since(start) < options.seconds / 2);
    const double elapsed = seconds_since(start);
    rollout_time += elapsed;
    rollout += static_cast<double>(n) / elapsed;
  }
  report.raw_steps_per_second = raw / 2;
  report.rollout_steps_per_second = rollout / 2;
  report.rollout_ratio = report.rollout_steps_per_second / report.raw_steps_per_second;
  report.rollouts_per_second_1 = static_cast<double>(rollouts) / rollout_time;
  report.threads = 1;
  return report;
}

}  // namespace diverse
