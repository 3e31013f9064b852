#include "task/seed_motion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "core/rng.h"
#include "core/thread_pool.h"
#include "optimize/cmaes.h"
#include "task/evaluate.h"

namespace diverse {
namespace {

constexpr double kMarginCap = 0.1;  // m; slack beyond this earns nothing more
constexpr int kPatience = 25;       // generations without improvement that end the last stage

struct Scored {
  double f = 0, constraint = 0, margin = 0;
  bool fell = true;
};

// Scores x on the task at its timestep and again with the timestep halved, and sums the
// two constraint values: a motion counts as meeting the task only if it does so at both
// timesteps, which keeps input motions away from knife-edge landings that depend on
// integration details. The sum (rather than checking the fine timestep only once the
// coarse one is met) keeps the landscape graded for CMA-ES: a candidate that meets the
// task coarsely but falls finely is ranked among the falls by how early it fell.
Scored score(const TaskEvaluator& ev, const TaskEvaluator& fine, const Eigen::VectorXd& x,
             SimWorker& worker, SimWorker& fine_worker) {
  EvaluationOptions options;
  options.samples_per_phase = 0;
  const Evaluation e = ev.evaluate_normalized(x, worker, options);
  const Evaluation f = fine.evaluate_normalized(x, fine_worker, options);
  Scored s;
  s.constraint = e.constraint + f.constraint;
  s.fell = e.fell || f.fell;
  s.margin = std::min(e.failed ? -1 : constraint_margin(ev.task(), e.summary),
                      f.failed ? -1 : constraint_margin(fine.task(), f.summary));
  const double reward = s.constraint == 0 ? std::min(std::max(s.margin, 0.0), kMarginCap) : 0;
  s.f = s.constraint - ev.task().seed.robustness * reward;
  return s;
}

Task halved(const Task& task, const mjModel* m) {
  Task t = task;
  t.simulation.timestep = 0.5 * m->opt.timestep;
  return t;
}

Task with_height(const Task& task, double height) {
  Task t = task;
  for (SceneObject& o : t.objects) {
    if (o.name == task.seed.object) o.height = height;
  }
  return t;
}

}  // namespace

SeedResult seed_motion(const Task& task, const ParameterSet& start, const SeedOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  SeedResult result;
  result.parameters = start;
  Eigen::VectorXd x = start.normalized();
  std::vector<double> heights = task.seed.heights;
  if (task.seed.object.empty()) heights = {-1};
  const int generations = options.generations > 0 ? options.generations : task.seed.generations;
  ThreadPool pool(std::max(1, options.threads));
  char line[256];

  for (size_t stage = 0; stage < heights.size(); ++stage) {
    const bool last = stage + 1 == heights.size();
    const Task stage_task = heights[stage] < 0 ? task : with_height(task, heights[stage]);
    const TaskEvaluator ev(stage_task);
    const TaskEvaluator fine(halved(stage_task, ev.model().get()));
    std::vector<std::unique_ptr<SimWorker>> workers, fine_workers;
    for (int w = 0; w < pool.size(); ++w) {
      workers.push_back(ev.make_worker());
      fine_workers.push_back(fine.make_worker());
    }

    Scored best = score(ev, fine, x, *workers[0], *fine_workers[0]);
    Eigen::VectorXd best_x = x;
    ++result.evaluations;
    if (options.log) {
      std::snprintf(line, sizeof(line), "stage %zu (height %.3f m): start C=%.6g margin=%.3f",
                    stage, heights[stage], best.constraint, best.margin);
      options.log(line);
    }
    if (!last && best.constraint == 0) continue;

    CmaesOptions co;
    co.dim = static_cast<int>(x.size());
    co.popsize = task.seed.popsize;
    co.sigma0 = task.seed.sigma;
    co.seed = derive_seed(task.seed.seed, {static_cast<std::uint64_t>(stage)});
    co.bounded = true;
    co.lower = 0;
    co.upper = 1;
    co.max_generations = generations;
    Cmaes es(co, x);
    int since_improvement = 0;
    while (es.stop_reason() == StopReason::kNone) {
      const std::vector<Eigen::VectorXd>& xs = es.ask();
      std::vector<Scored> scores(xs.size());
      pool.parallel_for(xs.size(), [&](std::size_t k, int worker) {
        const auto w = static_cast<std::size_t>(worker);
        scores[k] = score(ev, fine, xs[k], *workers[w], *fine_workers[w]);
      });
      std::vector<double> f(xs.size());
      bool improved = false;
      for (size_t k = 0; k < xs.size(); ++k) {
        f[k] = scores[k].f;
        if (scores[k].f < best.f) {
          best = scores[k];
          best_x = xs[k];
          improved = true;
        }
      }
      result.evaluations += static_cast<long long>(xs.size());
      es.tell(f);
      since_improvement = improved ? 0 : since_improvement + 1;
      if (options.log) {
        std::snprintf(line, sizeof(line),
                      "stage %zu gen %lld: best f=%.6g C=%.6g margin=%.3f sigma=%.4f", stage,
                      es.generation(), best.f, best.constraint, best.margin, es.sigma());
        options.log(line);
      }
      if (!last && best.constraint == 0) break;
      if (last && best.constraint == 0 &&
          (task.seed.robustness == 0 || since_improvement >= kPatience)) {
        break;
      }
    }
    x = best_x;
  }

  // The result on the full task.
  const TaskEvaluator ev(task);
  const TaskEvaluator fine(halved(task, ev.model().get()));
  auto worker = ev.make_worker();
  auto fine_worker = fine.make_worker();
  const Scored final_score = score(ev, fine, x, *worker, *fine_worker);
  result.parameters.set_normalized(x);
  result.constraint = final_score.constraint;
  result.margin = final_score.margin;
  result.fell = final_score.fell;
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace diverse
