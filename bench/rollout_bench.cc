// Rollout cost: simulated steps per second of a full task rollout (controller, contact
// scan, constraint monitor) without and with the step recorder, beside raw mj_step on the
// same model with zero ctrl. The rollout's "steps_per_s" counter is the figure to compare;
// docs/reference/controllers.md lists measured values.
//
//   diverse_bench --benchmark_filter='Rollout|RawStep'
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include "physics/model.h"
#include "task/evaluate.h"

namespace diverse {
namespace {

const std::string kTask = std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml";

struct Fixture {
  Fixture() : evaluator(load_task(kTask)) {
    params = evaluator.load_parameters(evaluator.task().m0);
  }
  TaskEvaluator evaluator;
  ParameterSet params;
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

// Raw mj_step with zero ctrl on the task's model, from the standing pose, for as many
// steps as the M0 rollout takes (the character slumps to the floor meanwhile).
void BM_RawStep(benchmark::State& state) {
  Fixture& f = fixture();
  auto worker = f.evaluator.make_worker();
  auto probe = f.evaluator.make_worker();
  const int steps = f.evaluator.evaluate(f.params.values(), *probe).stats.steps;
  long long total = 0;
  for (auto _ : state) {
    worker->reset();
    mjModel* m = worker->model();
    mjData* d = worker->data();
    for (int k = 0; k < steps; ++k) mj_step(m, d);
    benchmark::DoNotOptimize(d->qpos[0]);
    total += steps;
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(total), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RawStep)->Unit(benchmark::kMillisecond);

// Raw mj_step along the same trajectory as the rollout: the M0 rollout's recorded ctrl and
// damping replayed with plain mj_step (the physics cost of exactly that motion).
void BM_RawStepSameMotion(benchmark::State& state) {
  Fixture& f = fixture();
  auto worker = f.evaluator.make_worker();
  StepRecorder record;
  EvaluationOptions options;
  options.recorder = &record;
  f.evaluator.evaluate(f.params.values(), *worker, options);
  long long total = 0;
  for (auto _ : state) {
    worker->reset();
    mjModel* m = worker->model();
    mjData* d = worker->data();
    size_t change = 0;
    for (int k = 0; k < record.steps(); ++k) {
      while (change < record.damping.size() && record.damping[change].step == k) {
        for (int j = 0; j < record.ndamp; ++j) m->dof_damping[record.damped_dofs[j]] = record.damping[change].values[j];
        ++change;
      }
      for (int i = 0; i < m->nu; ++i) d->ctrl[i] = record.ctrl[static_cast<size_t>(k) * m->nu + i];
      mj_step(m, d);
    }
    benchmark::DoNotOptimize(d->qpos[0]);
    total += record.steps();
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(total), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RawStepSameMotion)->Unit(benchmark::kMillisecond);

void BM_Rollout(benchmark::State& state) {
  Fixture& f = fixture();
  auto worker = f.evaluator.make_worker();
  const bool record = state.range(0) != 0;
  long long total = 0;
  for (auto _ : state) {
    StepRecorder recorder;
    EvaluationOptions options;
    options.samples_per_phase = 10;
    options.recorder = record ? &recorder : nullptr;
    const Evaluation e = f.evaluator.evaluate(f.params.values(), *worker, options);
    benchmark::DoNotOptimize(e.constraint);
    total += e.stats.steps;
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(total), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Rollout)->Arg(0)->Arg(1)->ArgName("record")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace diverse
