// Per-generation overhead of the CMA-ES (ask + tell, no objective cost) at n = 100,
// lambda = 16, with and without the active update, beside an eager Eigen
// eigendecomposition of the same size. Reference figures on one core (docs/reference/cmaes.md):
// pycma 1.15 ms; libcmaes 0.93 ms (0.52 ms with lazy eigendecomposition), active
// 1.77 ms (1.36 ms lazy).
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <vector>

#include "core/rng.h"
#include "optimize/cmaes.h"
#include "optimize/test_functions.h"

namespace diverse {
namespace {

void BM_CmaesGeneration(benchmark::State& state) {
  CmaesOptions o;
  o.dim = static_cast<int>(state.range(0));
  o.popsize = static_cast<int>(state.range(1));
  o.active = state.range(2) != 0;
  o.seed = 1;
  Cmaes es(o, Eigen::VectorXd::Constant(o.dim, 0.5));
  // Random fitness: the strategy does all its work, the objective costs nothing.
  Rng fitness_rng(2);
  std::vector<double> fitness(es.popsize());
  for (auto _ : state) {
    const auto& xs = es.ask();
    benchmark::DoNotOptimize(xs.data());
    for (double& f : fitness) f = fitness_rng.uniform();
    es.tell(fitness);
  }
  state.counters["generations"] = static_cast<double>(es.generation());
}
BENCHMARK(BM_CmaesGeneration)
    ->ArgNames({"n", "lambda", "active"})
    ->Args({100, 16, 1})
    ->Args({100, 16, 0})
    ->Args({10, 10, 1})
    ->Args({30, 14, 1})
    ->Unit(benchmark::kMillisecond);

// What one eager decomposition per generation would cost.
void BM_EigenDecomposition(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Rng rng(3);
  Eigen::MatrixXd A(n, n);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) A(i, j) = rng.normal();
  }
  const Eigen::MatrixXd C = A * A.transpose() / n + Eigen::MatrixXd::Identity(n, n);
  for (auto _ : state) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(C, Eigen::ComputeEigenvectors);
    benchmark::DoNotOptimize(solver.eigenvalues().data());
  }
}
BENCHMARK(BM_EigenDecomposition)->Arg(100)->Unit(benchmark::kMillisecond);

// A whole run for scale: sphere in 30-D to f < 1e-10.
void BM_CmaesSphere30(benchmark::State& state) {
  for (auto _ : state) {
    CmaesOptions o;
    o.dim = 30;
    o.sigma0 = 0.5;
    o.target_f = 1e-10;
    Cmaes es(o, Eigen::VectorXd::Constant(30, 0.5));
    std::vector<double> fitness(es.popsize());
    while (es.stop_reason() == StopReason::kNone) {
      const auto& xs = es.ask();
      for (size_t k = 0; k < xs.size(); ++k) fitness[k] = sphere(xs[k]);
      es.tell(fitness);
    }
    benchmark::DoNotOptimize(es.best_f());
  }
}
BENCHMARK(BM_CmaesSphere30)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace diverse
