#include "eval/throughput.h"

#include <mujoco/mujoco.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>

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

double cpu_seconds(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double load_average() {
  double load[1] = {-1};
  return getloadavg(load, 1) == 1 ? load[0] : -1;
}

// Replays a record's inputs with plain mj_step, on its own copy of the model.
class RawReplay {
 public:
  RawReplay(const mjModel* shared, const StepRecorder& record)
      : m_(mj_copyModel(nullptr, shared)), d_(mj_makeData(m_)), record_(record) {}
  ~RawReplay() {
    mj_deleteData(d_);
    mj_deleteModel(m_);
  }
  RawReplay(const RawReplay&) = delete;
  RawReplay& operator=(const RawReplay&) = delete;

  // One replay of the whole record; returns its steps.
  long long once() {
    const StepRecorder& record = record_;
    mj_resetData(m_, d_);
    std::copy(record.qpos0.begin(), record.qpos0.end(), d_->qpos);
    std::copy(record.qvel0.begin(), record.qvel0.end(), d_->qvel);
    std::size_t change = 0;
    for (int k = 0; k < record.steps(); ++k) {
      while (change < record.damping.size() && record.damping[change].step == k) {
        for (int j = 0; j < record.ndamp; ++j)
          m_->dof_damping[record.damped_dofs[static_cast<std::size_t>(j)]] =
              record.damping[change].values[static_cast<std::size_t>(j)];
        ++change;
      }
      std::copy(record.ctrl.begin() + static_cast<long>(k) * record.nu,
                record.ctrl.begin() + static_cast<long>(k + 1) * record.nu, d_->ctrl);
      mj_step(m_, d_);
    }
    return record.steps();
  }

 private:
  mjModel* m_;
  mjData* d_;
  const StepRecorder& record_;
};

// Raw replay and rollout measured in alternation, one run of each at a time, for about
// 2 x `budget` wall seconds: a change in the machine's speed (other jobs, a host that
// steals the virtual CPU, the clock) lasting longer than a rollout hits both alike, which
// separate measurements of `budget` seconds each did not (their ratio spread by 20 points
// on an idle machine). Each run is timed in the measuring thread's CPU time.
struct Alternated {
  double raw_steps_per_second = 0;
  double rollout_steps_per_second = 0;
  long long rollouts = 0;
  double rollout_wall = 0;  // wall seconds spent in rollouts
};

Alternated alternate(double budget, bool raw_first, const std::function<long long()>& raw_once,
                     const std::function<long long()>& rollout_once) {
  long long raw_steps = 0, rollout_steps = 0;
  double raw_cpu = 0, rollout_cpu = 0;
  Alternated a;
  auto timed = [](const std::function<long long()>& run, long long* steps, double* cpu) {
    const double c0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
    *steps += run();
    *cpu += cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - c0;
  };
  const auto start = Clock::now();
  for (bool raw_turn = raw_first; seconds_since(start) < 2 * budget || a.rollouts == 0 || raw_steps == 0;
       raw_turn = !raw_turn) {
    if (raw_turn) {
      timed(raw_once, &raw_steps, &raw_cpu);
    } else {
      const auto w0 = Clock::now();
      timed(rollout_once, &rollout_steps, &rollout_cpu);
      a.rollout_wall += seconds_since(w0);
      ++a.rollouts;
    }
  }
  a.raw_steps_per_second = static_cast<double>(raw_steps) / std::max(1e-9, raw_cpu);
  a.rollout_steps_per_second = static_cast<double>(rollout_steps) / std::max(1e-9, rollout_cpu);
  return a;
}

double median_of(std::vector<double> v) { return Spread::of(std::move(v)).median; }

}  // namespace

Spread Spread::of(std::vector<double> values) {
  Spread s;
  s.rounds = values;
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  auto quantile = [&](double q) {
    const double at = q * static_cast<double>(values.size() - 1);
    const std::size_t lo = static_cast<std::size_t>(std::floor(at));
    const std::size_t hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (at - static_cast<double>(lo)) * (values[hi] - values[lo]);
  };
  s.median = quantile(0.5);
  s.min = values.front();
  s.max = values.back();
  s.q1 = quantile(0.25);
  s.q3 = quantile(0.75);
  return s;
}

nlohmann::json Spread::to_json() const {
  return {{"median", median}, {"min", min}, {"max", max}, {"q1", q1}, {"q3", q3}, {"rounds", rounds}};
}

nlohmann::json ThroughputReport::to_json() const {
  nlohmann::json j = {{"rounds", rounds},
                      {"seconds_per_measurement", seconds},
                      {"raw_mj_step_steps_per_second", raw_steps_per_second},
                      {"rollout_steps_per_second", rollout_steps_per_second},
                      {"rollout_over_raw", rollout_ratio},
                      {"rollout_over_raw_rounds", ratio.to_json()},
                      {"steps_per_rollout", rollout_steps},
                      {"rollouts_per_second_1_thread", rollouts_per_second_1},
                      {"threads", threads},
                      {"load_average_before", load_before},
                      {"load_average_after", load_after}};
  if (rollouts_per_second_n > 0) {
    j["rollouts_per_second_n_threads"] = rollouts_per_second_n;
    j["parallel_speedup"] = speedup;
    j["parallel_speedup_rounds"] = speedup_spread.to_json();
    j["cpu_share_n_threads"] = cpu_share.to_json();
    j["parallel_speedup_cpu_span_rounds"] = speedup_cpu.to_json();
  }
  return j;
}

ThroughputReport measure_throughput(const TaskEvaluator& evaluator, const ParameterSet& m0,
                                    const ThroughputOptions& options) {
  ThroughputReport report;
  report.rounds = std::max(1, options.rounds);
  report.seconds = options.seconds;
  report.load_before = load_average();
  auto worker = evaluator.make_worker();

  // M0's inputs, recorded once.
  StepRecorder record;
  EvaluationOptions recording;
  recording.recorder = &record;
  evaluator.evaluate(m0.values(), *worker, recording);
  report.rollout_steps = record.steps();

  // A batch of perturbed samples, as a generation of the optimizer, for the speed-up.
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
  struct Pool {
    ThreadPool pool;
    std::vector<std::unique_ptr<SimWorker>> workers;
    explicit Pool(int threads, const TaskEvaluator& evaluator) : pool(threads) {
      for (int w = 0; w < pool.size(); ++w) workers.push_back(evaluator.make_worker());
    }
  };
  Pool one(1, evaluator), many(report.threads, evaluator);
  // Rollouts per wall second of whole batches on `p`; the process's CPU share of its
  // threads' cores meanwhile; and rollouts per second of the batches' CPU span: each
  // batch lasts as long as its busiest thread's CPU time, which is how long it would
  // take on free cores (contention between the threads and an uneven end of the batch
  // count, time spent descheduled does not).
  struct Rates {
    double wall = 0, cpu_span = 0, share = 0;
  };
  auto batch_rate = [&](Pool& p) {
    long long rollouts = 0;
    double span = 0;
    std::vector<double> busy(static_cast<std::size_t>(p.pool.size()));
    const auto start = Clock::now();
    const double cpu0 = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID);
    do {
      std::fill(busy.begin(), busy.end(), 0.0);
      p.pool.parallel_for(batch.size(), [&](std::size_t i, int w) {
        const double t0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
        evaluator.evaluate_normalized(batch[i], *p.workers[static_cast<std::size_t>(w)]);
        busy[static_cast<std::size_t>(w)] += cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - t0;
      });
      span += *std::max_element(busy.begin(), busy.end());
      rollouts += static_cast<long long>(batch.size());
    } while (seconds_since(start) < options.seconds);
    const double wall = seconds_since(start);
    Rates r;
    r.wall = static_cast<double>(rollouts) / wall;
    r.cpu_span = static_cast<double>(rollouts) / std::max(1e-9, span);
    r.share = (cpu_seconds(CLOCK_PROCESS_CPUTIME_ID) - cpu0) / (wall * static_cast<double>(p.pool.size()));
    return r;
  };

  RawReplay raw(evaluator.model().get(), record);
  std::vector<double> raw_rate, rollout, ratio, rate1, rate_n, speedup, speedup_cpu, share;
  for (int round = 0; round < report.rounds; ++round) {
    Rates one_rate, n_rate;
    Alternated a;
    auto measure_steps = [&] {
      a = alternate(options.seconds, round % 2 == 0, [&] { return raw.once(); },
                    [&]() -> long long { return evaluator.evaluate(m0.values(), *worker).stats.steps; });
    };
    auto measure_one = [&] { one_rate = batch_rate(one); };
    auto measure_many = [&] { n_rate = batch_rate(many); };
    if (round % 2 == 0) {
      measure_steps(); measure_one(); measure_many();
    } else {
      measure_many(); measure_one(); measure_steps();
    }
    const double r = a.raw_steps_per_second, o = a.rollout_steps_per_second;
    raw_rate.push_back(r);
    rollout.push_back(o);
    ratio.push_back(o / r);
    rate1.push_back(one_rate.wall);
    rate_n.push_back(n_rate.wall);
    speedup.push_back(n_rate.wall / one_rate.wall);
    speedup_cpu.push_back(n_rate.cpu_span / one_rate.cpu_span);
    share.push_back(n_rate.share);
  }
  report.raw_steps_per_second = median_of(raw_rate);
  report.rollout_steps_per_second = median_of(rollout);
  report.ratio = Spread::of(ratio);
  report.rollout_ratio = report.ratio.median;
  report.rollouts_per_second_1 = median_of(rate1);
  report.rollouts_per_second_n = median_of(rate_n);
  report.speedup_spread = Spread::of(speedup);
  report.speedup = report.speedup_spread.median;
  report.cpu_share = Spread::of(share);
  report.speedup_cpu = Spread::of(speedup_cpu);
  report.load_after = load_average();
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
  report.rounds = std::max(1, options.rounds);
  report.seconds = options.seconds;
  report.load_before = load_average();
  StepRecorder record;
  stand(&record);
  report.rollout_steps = record.steps();
  RawReplay replay(model->get(), record);
  std::vector<double> raw, rollout, ratio, per_second;
  for (int round = 0; round < report.rounds; ++round) {
    const Alternated a = alternate(options.seconds, round % 2 == 0, [&] { return replay.once(); },
                                   [&]() -> long long { return stand(nullptr).steps; });
    const double r = a.raw_steps_per_second, o = a.rollout_steps_per_second;
    const long long rollouts = a.rollouts;
    const double wall = a.rollout_wall;
    raw.push_back(r);
    rollout.push_back(o);
    ratio.push_back(o / r);
    per_second.push_back(static_cast<double>(rollouts) / wall);
  }
  report.raw_steps_per_second = median_of(raw);
  report.rollout_steps_per_second = median_of(rollout);
  report.ratio = Spread::of(ratio);
  report.rollout_ratio = report.ratio.median;
  report.rollouts_per_second_1 = median_of(per_second);
  report.threads = 1;
  report.load_after = load_average();
  return report;
}

}  // namespace diverse
