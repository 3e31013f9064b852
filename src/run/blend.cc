#include "run/blend.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "core/error.h"
#include "core/rng.h"
#include "core/thread_pool.h"
#include "eval/motion_problem.h"
#include "finished/run_problem.h"
#include "finished/run_view.h"
#include "io/files.h"
#include "io/motion_record.h"

namespace diverse {
namespace fs = std::filesystem;

namespace {

std::string numbered(char prefix, std::size_t i) {
  std::string s(1, prefix);
  s.append(std::to_string(i));
  return s;
}

nlohmann::json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

// Distance between two outcomes, or NaN when it means nothing: a failed motion, or one
// whose pose samples do not correspond (it never flew, or never came down).
double distance_or_nan(const MotionProblem& problem, const Outcome& a, const Outcome& b) {
  if (is_failure(a) || is_failure(b)) return std::numeric_limits<double>::quiet_NaN();
  const auto& ma = static_cast<const MotionOutcome&>(a);
  const auto& mb = static_cast<const MotionOutcome&>(b);
  if (ma.features.poses.empty() || ma.features.poses.size() != mb.features.poses.size())
    return std::numeric_limits<double>::quiet_NaN();
  return problem.distance(a, b);
}

bool feasible(const Outcome& o) { return !is_failure(o) && o.constraint == 0.0; }

}  // namespace

Eigen::VectorXd blend_weights(int vertices, std::uint64_t seed, int k) {
  if (vertices < 1) throw std::invalid_argument("blend_weights: vertices must be >= 1");
  Rng rng(derive_seed(seed, {static_cast<std::uint64_t>(k)}));
  Eigen::VectorXd w(vertices);
  for (int i = 0; i < vertices; ++i) w[i] = -std::log1p(-rng.uniform());
  const double sum = w.sum();
  if (!(sum > 0)) return Eigen::VectorXd::Constant(vertices, 1.0 / vertices);
  return w / sum;
}

Eigen::VectorXd blend_point(std::span<const Eigen::VectorXd> points, const Eigen::VectorXd& weights) {
  if (points.empty() || static_cast<std::size_t>(weights.size()) != points.size())
    throw std::invalid_argument("blend_point: one weight per point expected");
  Eigen::VectorXd x = Eigen::VectorXd::Zero(points.front().size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].size() != x.size()) throw std::invalid_argument("blend_point: points of different sizes");
    x += weights[static_cast<Eigen::Index>(i)] * points[i];
  }
  // A convex combination of points in [0, 1] lies in [0, 1]; keep rounding from leaving it.
  return x.cwiseMax(0.0).cwiseMin(1.0);
}

nlohmann::json write_blend(const fs::path& run_dir, const BlendOptions& options) {
  if (options.samples < 1 || options.samples > 100000)
    throw UserError("--samples: expected 1 to 100000, got " + std::to_string(options.samples));
  if (options.path_points < 0 || options.path_points > 10000)
    throw UserError("--path-points: expected 0 to 10000, got " + std::to_string(options.path_points));
  const RunView run = load_run_view(run_dir);
  const RunProblem rp = open_run_problem(run, options.threads,
                                         "the blends cannot be simulated as the run simulated its motions (restore it)");
  const MotionProblem& problem = *rp.problem;
  ThreadPool pool(problem.workers());
  const std::size_t count = rp.motions.size();  // N + 1
  const int K = options.samples;

  // The run's motions again (the distances need their pose samples), the blends, and the
  // path points, in one batch.
  std::vector<Eigen::VectorXd> weights;
  std::vector<Eigen::VectorXd> points;
  for (int k = 1; k <= K; ++k) {
    weights.push_back(blend_weights(static_cast<int>(count), options.seed, k));
    points.push_back(blend_point(rp.motions, weights.back()));
  }
  struct PathJob {
    std::size_t variation;
    std::size_t point;
    Eigen::VectorXd x;
  };
  std::vector<PathJob> path_jobs;
  std::vector<std::size_t> path_totals(count, 0);
  for (std::size_t v = 1; v < count && options.path_points > 0; ++v) {
    // Where the variation stood after its steps, without the start (M0 itself) and the
    // result (the motion the run returned): the points between.
    const std::vector<RunPathPoint> path = read_run_path(run, v, rp.like);
    std::vector<std::size_t> inner;
    for (std::size_t k = 0; k < path.size(); ++k)
      if (!path[k].result && path[k].generation > 0) inner.push_back(k);
    path_totals[v] = inner.size();
    const std::size_t want = static_cast<std::size_t>(options.path_points);
    std::size_t previous = std::numeric_limits<std::size_t>::max();
    for (std::size_t j = 0; j < std::min(inner.size(), want); ++j) {
      const std::size_t at = inner.size() <= want
                                 ? j
                                 : static_cast<std::size_t>(std::llround(static_cast<double>(j) * (inner.size() - 1) /
                                                                         static_cast<double>(want - 1)));
      if (at == previous) continue;
      previous = at;
      path_jobs.push_back({v, inner[at], path[inner[at]].x});
    }
  }

  const fs::path dir = run.dir / "blend";
  // The whole directory is replaced: no blend of an earlier, larger K stays behind.
  std::error_code error;
  fs::remove_all(dir, error);
  if (error) throw UserError(dir.string() + ": cannot remove the previous blends: " + error.message());
  fs::create_directories(dir / "motions");

  std::vector<std::shared_ptr<const Outcome>> motion_out(count), blend_out(static_cast<std::size_t>(K)),
      path_out(path_jobs.size());
  const std::size_t jobs = count + static_cast<std::size_t>(K) + path_jobs.size();
  pool.parallel_for(jobs, [&](std::size_t j, int worker) {
    if (j < count) {
      motion_out[j] = problem.evaluate_confirmed(rp.motions[j], worker);
    } else if (j < count + static_cast<std::size_t>(K)) {
      const std::size_t k = j - count;
      blend_out[k] = problem.evaluate_confirmed(points[k], worker);
      // The blend as a motion file: simulated again with recording on, on its own body.
      const std::string stem = numbered('b', k + 1);
      write_motion(*rp.evaluator, problem.named(points[k]), {numbered('B', k + 1), dir / "model" / (stem + ".xml")},
                   dir / "motions" / (stem + ".json"));
    } else {
      const PathJob& p = path_jobs[j - count - static_cast<std::size_t>(K)];
      path_out[j - count - static_cast<std::size_t>(K)] = problem.evaluate_confirmed(p.x, worker);
    }
  });

  nlohmann::json labels = nlohmann::json::array();
  nlohmann::json motions = nlohmann::json::array();
  for (std::size_t i = 0; i < count; ++i) {
    labels.push_back(run.motions[i].label);
    motions.push_back({{"label", run.motions[i].label},
                       {"constraint", number_or_null(motion_out[i]->constraint)},
                       {"failed", motion_out[i]->failed}});
  }
  nlohmann::json blends = nlohmann::json::array();
  int feasible_count = 0;
  double nearest_sum = 0, nearest_max = 0;
  int nearest_count = 0;
  for (int k = 0; k < K; ++k) {
    const Outcome& o = *blend_out[static_cast<std::size_t>(k)];
    const auto& mo = static_cast<const MotionOutcome&>(o);
    nlohmann::json w = nlohmann::json::array(), d = nlohmann::json::array();
    int nearest = -1;
    double nearest_d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < count; ++i) {
      w.push_back(weights[static_cast<std::size_t>(k)][static_cast<Eigen::Index>(i)]);
      const double di = distance_or_nan(problem, o, *motion_out[i]);
      d.push_back(number_or_null(di));
      if (std::isfinite(di) && di < nearest_d) {
        nearest_d = di;
        nearest = static_cast<int>(i);
      }
    }
    const bool ok = feasible(o);
    if (ok) {
      ++feasible_count;
      if (nearest >= 0) {
        nearest_sum += nearest_d;
        nearest_max = std::max(nearest_max, nearest_d);
        ++nearest_count;
      }
    }
    const std::string stem = numbered('b', static_cast<std::size_t>(k) + 1);
    blends.push_back({{"index", k + 1},
                      {"label", numbered('B', static_cast<std::size_t>(k) + 1)},
                      {"file", "motions/" + stem + ".json"},
                      {"weights", w},
                      {"constraint", number_or_null(o.constraint)},
                      {"fell", mo.fell},
                      {"failed", o.failed},
                      {"feasible", ok},
                      {"distances", d},
                      {"nearest", nearest >= 0 ? nlohmann::json(nearest) : nlohmann::json(nullptr)}});
  }

  nlohmann::json path_variations = nlohmann::json::array();
  int path_feasible = 0;
  for (std::size_t v = 1; v < count; ++v) {
    int n = 0, ok = 0;
    for (std::size_t j = 0; j < path_jobs.size(); ++j) {
      if (path_jobs[j].variation != v) continue;
      ++n;
      if (feasible(*path_out[j])) ++ok;
    }
    path_feasible += ok;
    path_variations.push_back({{"variation", v}, {"points_total", path_totals[v]}, {"points", n}, {"feasible", ok}});
  }
  const auto fraction = [](int part, std::size_t whole) {
    return whole > 0 ? nlohmann::json(static_cast<double>(part) / static_cast<double>(whole)) : nlohmann::json(nullptr);
  };

  nlohmann::json summary = {
      {"format", "diverse.blend"},
      {"version", 1},
      {"task", run.task_name},
      {"metric", run.metric},
      {"run_fingerprint", run_fingerprint(run)},
      {"vary", rp.vary_shape ? nlohmann::json::array({"control", "shape"}) : nlohmann::json::array({"control"})},
      {"seed", options.seed},
      {"samples", K},
      {"vertices", count},
      {"labels", labels},
      {"feasible", feasible_count},
      {"feasible_fraction", fraction(feasible_count, static_cast<std::size_t>(K))},
      {"feasible_nearest_distance",
       {{"mean", nearest_count > 0 ? nlohmann::json(nearest_sum / nearest_count) : nlohmann::json(nullptr)},
        {"max", nearest_count > 0 ? nlohmann::json(nearest_max) : nlohmann::json(nullptr)}}},
      {"motions", motions},
      {"paths",
       {{"points_per_variation", options.path_points},
        {"points", path_jobs.size()},
        {"feasible", path_feasible},
        {"feasible_fraction", fraction(path_feasible, path_jobs.size())},
        {"variations", path_variations}}},
      {"blends", blends}};
  write_json_atomic(dir / "summary.json", summary);
  return summary;
}

}  // namespace diverse
