// `diverse run [TASK]` and `diverse resume DIR`: diverse motions for a task.
//
//   diverse run backflip --n 4 --generations 500 --out runs/backflip
//   diverse run backflip --vary shape --metric shape --out runs/backflip-shapes
//   diverse resume runs/backflip
// mpirun -n 8 --hostfile hosts diverse run backflip --out runs/backflip
// (docs/guide/running-at-scale.md)
//
// See src/run/run.h for what a run directory holds.
#include <CLI/CLI.hpp>

#include <string>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "distribute/cluster.h"
#include "metric/metric.h"
#include "optimize/diversity.h"
#include "run/run.h"
#include "task/task.h"

namespace diverse::cli {
namespace {

constexpr const char* kDefaultTask = "jump_high";
constexpr double kMaxCheckpointSeconds = 86400;
constexpr double kMaxRankTimeoutSeconds = 86400;

// --rank-timeout of run and resume (distribute/cluster.h).
void add_rank_timeout(CLI::App* cmd, double* seconds) {
  cmd->add_option("--rank-timeout", *seconds,
                  "Under mpirun: seconds rank 0 waits for a word from a worker rank holding samples "
                  "before it ends the run naming that rank")
      ->capture_default_str()
      ->check(number_in(kMinRankTimeoutSeconds, kMaxRankTimeoutSeconds));
}

struct RunArgs {
  std::string task = kDefaultTask;
  int n = 0;
  std::string metric;
  std::string vary = "control";
  double shape_weight = kDefaultShapeWeight;
  double k = 10.0;
  long long generations = 0;  // 0 = the task's (diversity.generations, default 500)
  std::string strategy = "round-robin";
  std::string constraints = "dominant";
  std::string point = "best-sample";
  std::uint64_t seed = 1;
  int threads = 0;
  int popsize = 16;
  double sigma0 = 0.0;  // 0 = the task's (diversity.sigma0, default 0.1)
  int window = 100;
  double epsilon = 1e-6;
  std::string out;
  bool force = false;
  bool quiet = false;
  bool no_render = false;
  double checkpoint_seconds = 5.0;
  double strength = 1.0;
  double effort_bound = 0.0;  // 0 = none
  bool robust = false;
  double max_distance = 0.0;  // 0 = none
  double rank_timeout = kDefaultRankTimeoutSeconds;
};

void install_run(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Find N diverse variations of a task's input motion (default task: jump_high)");
  cmd->footer("Examples:\n"
              "  diverse run                          # 4 diverse high jumps into runs/jump_high/\n"
              "  diverse run backflip --seed 2        # another task and seed\n"
              "  diverse run jump_forward --vary shape --metric shape  # body shapes");
  cmd->add_option("task", args->task, "Task name (tasks/<name>.toml) or path to a task file")
      ->capture_default_str();
  cmd->add_option("--n", args->n, "Number of variations N (default: the task's, 4)")
      ->check(integer_in(1, kMaxVariations));
  cmd->add_option("--metric", args->metric,
                  "Distance metric: hf, md or wja (motion), shape (body shape; needs --vary shape), "
                  "or a motion metric plus the weighted shape distance: hf+shape, md+shape, "
                  "wja+shape (default: the task's)");
  cmd->add_option("--vary", args->vary,
                  "What the variations may change: control (the controller's parameters) or "
                  "shape (the controller's parameters and the body's link-length scales, the "
                  "character file's [shape] parameters)")
      ->capture_default_str();
  cmd->add_option("--shape-weight", args->shape_weight,
                  "Weight of the shape distance (m) in a combined metric such as md+shape, in "
                  "units of the motion metric per metre")
      ->capture_default_str()
      ->check(number_in(0, 1e9, Bound::kOpen));
  cmd->add_option("--k", args->k, "Weight K of the dmin term (paper: 10)")
      ->capture_default_str()
      ->check(number_in(0, 1e9));
  cmd->add_option("--generations", args->generations,
                  "Generation limit (default: the task's [diversity] generations, 500 unless "
                  "it says)")
      ->check(integer_in(1, kMaxGenerations));
  cmd->add_option("--strategy", args->strategy, "round-robin, progressive, joint or simultaneous")
      ->capture_default_str();
  cmd->add_option("--constraints", args->constraints,
                  "dominant (a violating sample ranks below every feasible one) or penalty "
                  "(eq. 1 literally: -C inside D)")
      ->capture_default_str();
  cmd->add_option("--point", args->point,
                  "Where a variation stands between its steps: best-sample (its best sample "
                  "so far) or mean (its CMA mean, as in the paper)")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "Random seed")->capture_default_str()->check(unsigned_integer());
  cmd->add_option("--threads", args->threads, "Worker threads (0 = one per core)")
      ->capture_default_str()
      ->check(integer_in(0, kMaxThreads));
  cmd->add_option("--popsize", args->popsize, "CMA-ES samples per generation (lambda)")
      ->capture_default_str()
      ->check(integer_in(2, kMaxPopsize));
  cmd->add_option("--sigma0", args->sigma0,
                  "Initial CMA-ES step, in normalized units (default: the task's, 0.1 unless "
                  "its [diversity] table says otherwise)")
      ->check(number_in(0, 1, Bound::kOpen));
  cmd->add_option("--window", args->window,
                  "Stop when D improves by less than --epsilon over this many generations (0 = off)")
      ->capture_default_str()
      ->check(integer_in(0, kMaxGenerations));
  cmd->add_option("--epsilon", args->epsilon, "See --window")
      ->capture_default_str()
      ->check(number_in(0, 1e12));
  cmd->add_option("--strength", args->strength,
                  "Strength model: every joint's PD gains and torque limits times S (paper: "
                  "1.5 to 3 for a 'supernatural' character); saved models carry the limits")
      ->capture_default_str()
      ->check(number_in(kMinStrength, kMaxStrength));
  cmd->add_option("--effort-bound", args->effort_bound,
                  "Keep every variation's control effort (time integral of the squared net "
                  "joint torques) within R times the input motion's, R >= 1 (default: no bound)")
      ->check(number_in(kMinEffortBound, kMaxEffortBound));
  cmd->add_option("--max-distance", args->max_distance,
                  "Keep every variation within X of the input motion in the run's metric, X > 0 "
                  "(default: no bound)")
      ->check(number_in(0, kMaxDistanceBound, Bound::kOpen));
  cmd->add_flag("--robust", args->robust,
                "A sample meets the task only if it also holds under a small seeded part of the "
                "robustness suite (2 parameter perturbations, 2 pushes in the landing), judged "
                "where a variation would move to it (docs/guide/robustness.md)");
  cmd->add_option("--out", args->out, "Run directory (default: runs/<task>)");
  cmd->add_flag("--force", args->force, "Replace an existing run in the output directory");
  cmd->add_flag("--quiet", args->quiet, "No progress output");
  cmd->add_flag("--no-render", args->no_render, "Do not write filmstrip.png");
  cmd->add_option("--checkpoint-seconds", args->checkpoint_seconds,
                  "Wall seconds between checkpoints (0 = every generation)")
      ->capture_default_str()
      ->check(number_in(0, kMaxCheckpointSeconds));
  add_rank_timeout(cmd, &args->rank_timeout);
  cmd->callback([args] {
    const RunArgs& a = *args;
    // Ranges are checked by the options' validators (options.h); n = 0, sigma0 = 0 and
    // generations = 0 (never accepted from the command line) stand for the task's own values.
    if (a.vary != "control" && a.vary != "shape")
      throw UserError("--vary: expected control or shape, got '" + a.vary + "'");
    if (!a.metric.empty()) parse_distance(a.metric, a.shape_weight);
    RunRequest request;
    request.task = a.task;
    request.metric = a.metric;
    request.vary_shape = a.vary == "shape";
    request.shape_weight = a.shape_weight;
    request.options.variations = a.n;
    request.options.k = a.k;
    request.options.max_generations = a.generations;
    request.options.strategy = parse_strategy(a.strategy);
    request.options.constraints = parse_constraint_rule(a.constraints);
    request.options.point = parse_variation_point(a.point);
    request.options.seed = a.seed;
    request.options.popsize = a.popsize;
    request.options.sigma0 = a.sigma0;
    request.options.window = a.window;
    request.options.epsilon = a.epsilon;
    request.threads = a.threads;
    request.force = a.force;
    request.quiet = a.quiet;
    request.render = !a.no_render;
    request.checkpoint_seconds = a.checkpoint_seconds;
    request.strength = a.strength;
    request.bounds.effort = a.effort_bound;
    request.bounds.distance = a.max_distance;
    request.bounds.robust = a.robust;
    std::string task_name = a.task;
    if (const auto slash = task_name.find_last_of('/'); slash != std::string::npos)
      task_name = task_name.substr(slash + 1);
    if (const auto dot = task_name.rfind(".toml"); dot != std::string::npos)
      task_name = task_name.substr(0, dot);
    request.out = a.out.empty() ? "runs/" + task_name : a.out;
    // Under mpirun with several ranks, rank 0 runs and the others evaluate its samples.
    const auto cluster = Cluster::join();
    if (cluster && cluster->rank() > 0) return serve_run(*cluster, a.threads);
    if (cluster) cluster->set_rank_timeout(a.rank_timeout);
    request.cluster = cluster.get();
    start_run(request);
  });
}

void install_resume(CLI::App& app) {
  auto dir = std::make_shared<std::string>();
  auto threads = std::make_shared<int>(0);
  auto quiet = std::make_shared<bool>(false);
  auto checkpoint_seconds = std::make_shared<double>(5.0);
  auto no_render = std::make_shared<bool>(false);
  auto rank_timeout = std::make_shared<double>(kDefaultRankTimeoutSeconds);
  CLI::App* cmd = app.add_subcommand("resume", "Continue an interrupted run from its checkpoint");
  cmd->footer("Example:\n"
              "  diverse resume runs/jump_high        # the same result as a run never stopped");
  cmd->add_option("dir", *dir, "Run directory")->required();
  cmd->add_option("--threads", *threads, "Worker threads (0 = one per core)")
      ->capture_default_str()
      ->check(integer_in(0, kMaxThreads));
  cmd->add_flag("--quiet", *quiet, "No progress output");
  cmd->add_flag("--no-render", *no_render, "Do not write filmstrip.png");
  cmd->add_option("--checkpoint-seconds", *checkpoint_seconds,
                  "Wall seconds between checkpoints (0 = every generation)")
      ->capture_default_str()
      ->check(number_in(0, kMaxCheckpointSeconds));
  add_rank_timeout(cmd, rank_timeout.get());
  cmd->callback([dir, threads, quiet, checkpoint_seconds, no_render, rank_timeout] {
    const auto cluster = Cluster::join();
    if (cluster && cluster->rank() > 0) return serve_run(*cluster, *threads);
    if (cluster) cluster->set_rank_timeout(*rank_timeout);
    resume_run(*dir, *threads, *quiet, *checkpoint_seconds, !*no_render, cluster.get());
  });
}

const bool registered_run = register_command(30, install_run);
const bool registered_resume = register_command(31, install_resume);

}  // namespace
}  // namespace diverse::cli
