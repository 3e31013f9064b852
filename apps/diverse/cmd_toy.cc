// `diverse toy`: diversity optimization on the 2-D toy domain (paper figure 2).
//
//   diverse toy --k 10 --n 4 --seed 1 --out runs/toy-k10
//
// Writes OUT/summary.json (settings, points, D, C, dmin, pairwise distances, clustering
// and reach figures, paths) and OUT/toy.svg (region, reference in red, points, paths).
// With --seeds M, runs seeds SEED..SEED+M-1 into OUT/seed-<s>/ and writes the mean and
// sd of the figures over seeds to OUT/summary.json. See docs/guide/toy.md.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "core/thread_pool.h"
#include "io/files.h"
#include "optimize/diversity.h"
#include "toy/toy.h"

namespace diverse::cli {
namespace {

struct ToyArgs {
  double k = 10.0;
  int n = 4;
  std::uint64_t seed = 1;
  std::string out;
  long long generations = 200;
  std::string strategy = "round-robin";
  std::string constraints = "penalty";
  int threads = 1;
  bool paths = true;
  int seeds = 1;
};

std::string format_number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

nlohmann::json point_json(const Eigen::Vector2d& p) { return {p.x(), p.y()}; }

void validate(const ToyArgs& args) {
  if (!(args.k >= 0.0)) throw UserError("--k: expected a number >= 0, got " + format_number(args.k));
  if (args.n < 1) throw UserError("--n: expected an integer >= 1, got " + std::to_string(args.n));
  if (args.generations < 1) {
    throw UserError("--generations: expected an integer >= 1, got " +
                    std::to_string(args.generations));
  }
  if (args.threads < 1) {
    throw UserError("--threads: expected an integer >= 1, got " + std::to_string(args.threads));
  }
  if (args.seeds < 1) {
    throw UserError("--seeds: expected an integer >= 1, got " + std::to_string(args.seeds));
  }
}

// One optimization; writes DIR/summary.json and DIR/toy.svg and returns the summary.
nlohmann::json run_one(const ToyArgs& args, const DiversityOptions& options,
                       const ToyProblem& problem, ThreadPool& pool,
                       const std::filesystem::path& dir) {
  DiversityOptimizer optimizer(problem, options, pool);
  optimizer.run();
  const DiversityResult result = optimizer.result();

  std::vector<Eigen::Vector2d> points;
  for (std::size_t i = 1; i < result.parameters.size(); ++i) {
    points.push_back(result.parameters[i].head<2>());
  }
  std::vector<std::vector<Eigen::Vector2d>> paths;
  for (std::size_t v = 1; v < optimizer.paths().size(); ++v) {
    std::vector<Eigen::Vector2d> path;
    for (const auto& p : optimizer.paths()[v]) path.push_back(p.x.head<2>());
    paths.push_back(std::move(path));
  }
  const ToyFigures figures = toy_figures(problem.region(), points);
  const auto& score = result.score;

  nlohmann::json summary;
  nlohmann::json region = nlohmann::json::array();
  for (const auto& v : problem.region().polygon) region.push_back(point_json(v));
  summary["domain"] = {{"region", region},
                       {"reference", point_json(problem.region().reference)},
                       {"penalty", problem.penalty()},
                       {"distance", "squared euclidean"}};
  summary["settings"] = to_json(options);
  summary["settings"]["threads"] = args.threads;
  summary["generations"] = result.generations;
  summary["evaluations"] = result.evaluations;
  summary["stop"] = to_string(result.stop);
  summary["D"] = score.D;
  nlohmann::json pts = nlohmann::json::array();
  for (const auto& p : points) pts.push_back(point_json(p));
  summary["points"] = pts;
  summary["constraint"] = std::vector<double>(score.constraint.data(),
                                              score.constraint.data() + score.constraint.size());
  summary["dmin"] = std::vector<double>(score.dmin.data(), score.dmin.data() + score.dmin.size());
  nlohmann::json distances = nlohmann::json::array();
  for (Eigen::Index i = 0; i < score.distance.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < score.distance.cols(); ++j) row.push_back(score.distance(i, j));
    distances.push_back(row);
  }
  summary["distances"] = distances;
  summary["clustering"] = figures.clustering;
  summary["reach"] = figures.reach;
  summary["max_constraint"] = score.constraint.maxCoeff();
  nlohmann::json path_json = nlohmann::json::array();
  for (const auto& path : paths) {
    nlohmann::json p = nlohmann::json::array();
    for (const auto& x : path) p.push_back(point_json(x));
    path_json.push_back(p);
  }
  summary["paths"] = path_json;

  write_json_atomic(dir / "summary.json", summary);
  char title[160];
  std::snprintf(title, sizeof title, "K = %g, N = %d, %s, seed %llu: D = %.3f", options.k,
                options.variations, to_string(options.strategy),
                static_cast<unsigned long long>(options.seed), score.D);
  if (!args.paths) paths.clear();
  write_file_atomic(dir / "toy.svg", toy_svg(problem.region(), points, paths, title));
  return summary;
}

nlohmann::json mean_sd(const std::vector<double>& values) {
  double mean = 0.0;
  for (double v : values) mean += v;
  mean /= static_cast<double>(values.size());
  double var = 0.0;
  for (double v : values) var += (v - mean) * (v - mean);
  const double sd = values.size() > 1 ? std::sqrt(var / static_cast<double>(values.size() - 1)) : 0.0;
  return {{"mean", mean}, {"sd", sd}};
}

void run_toy(const ToyArgs& args) {
  validate(args);
  DiversityOptions options;
  options.k = args.k;
  options.variations = args.n;
  options.max_generations = args.generations;
  options.strategy = parse_strategy(args.strategy, "--strategy");
  options.constraints = parse_constraint_rule(args.constraints, "--constraints");
  const std::filesystem::path out(args.out);
  ensure_writable_directory(out);

  const ToyProblem problem;
  ThreadPool pool(args.threads);
  if (args.seeds == 1) {
    options.seed = args.seed;
    const nlohmann::json s = run_one(args, options, problem, pool, out);
    std::printf("D = %.6g  clustering = %.3f  reach = %.3f  max C = %.3g  "
                "(%lld generations, %lld evaluations, %s)\n",
                s["D"].get<double>(), s["clustering"].get<double>(), s["reach"].get<double>(),
                s["max_constraint"].get<double>(), s["generations"].get<long long>(),
                s["evaluations"].get<long long>(), s["stop"].get<std::string>().c_str());
    return;
  }

  // Several seeds: one run directory each, and the figures' mean and sd over seeds.
  std::vector<double> clustering, reach, max_c, d;
  nlohmann::json runs = nlohmann::json::array();
  for (int i = 0; i < args.seeds; ++i) {
    options.seed = args.seed + static_cast<std::uint64_t>(i);
    const std::string name = "seed-" + std::to_string(options.seed);
    const nlohmann::json s = run_one(args, options, problem, pool, out / name);
    clustering.push_back(s["clustering"].get<double>());
    reach.push_back(s["reach"].get<double>());
    max_c.push_back(s["max_constraint"].get<double>());
    d.push_back(s["D"].get<double>());
    runs.push_back({{"seed", options.seed}, {"dir", name}, {"D", d.back()},
                    {"clustering", clustering.back()}, {"reach", reach.back()},
                    {"max_constraint", max_c.back()}});
  }
  nlohmann::json summary;
  summary["settings"] = to_json(options);
  summary["settings"].erase("seed");
  summary["settings"]["first_seed"] = args.seed;
  summary["settings"]["seeds"] = args.seeds;
  summary["settings"]["threads"] = args.threads;
  summary["runs"] = runs;
  summary["D"] = mean_sd(d);
  summary["clustering"] = mean_sd(clustering);
  summary["reach"] = mean_sd(reach);
  summary["max_constraint"] = mean_sd(max_c);
  write_json_atomic(out / "summary.json", summary);
  auto ms = [&](const char* key) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.3f +- %.3f", summary[key]["mean"].get<double>(),
                  summary[key]["sd"].get<double>());
    return std::string(buffer);
  };
  char max_c_text[64];
  std::snprintf(max_c_text, sizeof max_c_text, "%.3g +- %.3g",
                summary["max_constraint"]["mean"].get<double>(),
                summary["max_constraint"]["sd"].get<double>());
  std::printf("K = %g, %d seeds: clustering = %s  reach = %s  max C = %s\n", args.k, args.seeds,
              ms("clustering").c_str(), ms("reach").c_str(), max_c_text);
}

void add_toy(CLI::App& app) {
  auto args = std::make_shared<ToyArgs>();
  CLI::App* cmd = app.add_subcommand(
      "toy", "Diversity optimization of points in a 2-D region (paper figure 2)");
  cmd->footer("Examples:\n"
              "  diverse toy --out runs/toy           # N = 4 points, K = 10\n"
              "  diverse toy --out runs/toy-k0 --k 0 --seeds 10");
  cmd->add_option("--k", args->k, "weight K of the dmin term (>= 0)")
      ->capture_default_str()
      ->check(number_in(0, 1e9));
  cmd->add_option("--n", args->n, "number of synthesized points N (>= 1)")
      ->capture_default_str()
      ->check(integer_in(1, kMaxVariations));
  cmd->add_option("--seed", args->seed, "run seed")->capture_default_str()->check(unsigned_integer());
  cmd->add_option("--out", args->out, "output directory")->required();
  cmd->add_option("--generations", args->generations, "generation limit")
      ->capture_default_str()
      ->check(integer_in(1, kMaxGenerations));
  cmd->add_option("--strategy", args->strategy, "round-robin, progressive, joint or simultaneous")
      ->capture_default_str();
  cmd->add_option("--constraints", args->constraints,
                  "dominant (a violating sample ranks below every feasible one) or penalty "
                  "(eq. 1 literally: -C inside D)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "worker threads")
      ->capture_default_str()
      ->check(integer_in(1, kMaxThreads));
  cmd->add_option("--seeds", args->seeds,
                  "run this many seeds (SEED, SEED+1, ...) into OUT/seed-<s>/ and summarize them")
      ->capture_default_str()
      ->check(integer_in(1, 10000));
  cmd->add_flag("!--no-paths", args->paths, "leave the optimization paths out of toy.svg");
  cmd->callback([args] { run_toy(*args); });
}

const bool registered = register_command(20, add_toy);

}  // namespace
}  // namespace diverse::cli
