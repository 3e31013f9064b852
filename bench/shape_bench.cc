// Cost of a shaped model beside the rollout it is built for: rewriting the backflip
// scene's MJCF for a random shape, compiling it (mj_loadXML from memory), and the per-sample
// setup a worker needs (character map, private model copy and mjData), against one
// backflip rollout of M0 on the base model. BM_ShapeBuild reports "rollout_fraction", its
// CPU time over the rollout's (goal: < 0.1); docs/guide/shapes.md lists measured values.
//
//   diverse_bench --benchmark_filter='Shape|BackflipRollout'
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "character/character.h"
#include "character/shape.h"
#include "core/rng.h"
#include "physics/model.h"
#include "task/evaluate.h"

namespace diverse {
namespace {

const std::string kTask = std::string(DIVERSE_SOURCE_DIR) + "/tasks/backflip.toml";

// CPU seconds of this thread: other processes on the machine do not count.
double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct Fixture {
  Fixture() : evaluator(load_task(kTask)), shapes(scene_xml(evaluator.task()), *evaluator.task().character_spec, evaluator.task().model) {
    params = evaluator.load_parameters(evaluator.task().m0);
    // Median CPU time of a few M0 rollouts, for the ratio.
    auto worker = evaluator.make_worker();
    std::vector<double> times;
    for (int k = 0; k < 7; ++k) {
      const double start = thread_seconds();
      const Evaluation e = evaluator.evaluate(params.values(), *worker);
      benchmark::DoNotOptimize(e.constraint);
      times.push_back(thread_seconds() - start);
    }
    std::sort(times.begin(), times.end());
    rollout_seconds = times[times.size() / 2];
  }
  TaskEvaluator evaluator;
  ShapeSpace shapes;
  ParameterSet params;
  double rollout_seconds = 0;
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

Eigen::VectorXd random_shape(const ShapeSpace& space, Rng& rng) {
  Eigen::VectorXd scales(space.size());
  for (int p = 0; p < space.size(); ++p) {
    const ParamSpec& s = space.specs()[static_cast<size_t>(p)];
    scales[p] = s.lower + (s.upper - s.lower) * rng.uniform();
  }
  return scales;
}

// The text rewrite alone.
void BM_ShapeXml(benchmark::State& state) {
  Fixture& f = fixture();
  Rng rng(1);
  for (auto _ : state) {
    const std::string xml = f.shapes.xml(random_shape(f.shapes, rng));
    benchmark::DoNotOptimize(xml.data());
  }
}
BENCHMARK(BM_ShapeXml)->Unit(benchmark::kMicrosecond);

// Rewrite and MuJoCo compile.
void BM_ShapeCompile(benchmark::State& state) {
  Fixture& f = fixture();
  Rng rng(2);
  for (auto _ : state) {
    auto model = f.shapes.compile(random_shape(f.shapes, rng));
    benchmark::DoNotOptimize(model->get()->body_inertia[0]);
  }
}
BENCHMARK(BM_ShapeCompile)->Unit(benchmark::kMillisecond);

// Everything a sample with a new shape needs before its rollout can start.
void BM_ShapeBuild(benchmark::State& state) {
  Fixture& f = fixture();
  Rng rng(3);
  const double start = thread_seconds();
  for (auto _ : state) {
    auto model = f.shapes.compile(random_shape(f.shapes, rng));
    const Character body = bind_character(f.evaluator.task().character_spec, model->get(), "shape");
    SimWorker worker(model);
    worker.reset();
    benchmark::DoNotOptimize(worker.data()->qpos[0]);
    benchmark::DoNotOptimize(body.total_mass);
  }
  const double seconds = thread_seconds() - start;
  state.counters["rollout_cpu_ms"] = 1e3 * f.rollout_seconds;
  state.counters["rollout_fraction"] = seconds / static_cast<double>(state.iterations()) / f.rollout_seconds;
}
BENCHMARK(BM_ShapeBuild)->Unit(benchmark::kMillisecond);

// The worker part of BM_ShapeBuild on the base model: private model copy, mjData, reset.
void BM_WorkerSetup(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) {
    SimWorker worker(f.evaluator.model_ptr());
    worker.reset();
    benchmark::DoNotOptimize(worker.data()->qpos[0]);
  }
}
BENCHMARK(BM_WorkerSetup)->Unit(benchmark::kMillisecond);

// One backflip rollout of M0 (base shape), as the optimizer runs it (pose samples, no
// recorder).
void BM_BackflipRollout(benchmark::State& state) {
  Fixture& f = fixture();
  auto worker = f.evaluator.make_worker();
  long long steps = 0;
  for (auto _ : state) {
    const Evaluation e = f.evaluator.evaluate(f.params.values(), *worker);
    benchmark::DoNotOptimize(e.constraint);
    steps += e.stats.steps;
  }
  state.counters["steps"] = static_cast<double>(steps) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_BackflipRollout)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace diverse
