#include "run/run.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <sstream>

#include "core/error.h"
#include "core/thread_pool.h"
#include "distribute/cluster.h"
#include "eval/motion_problem.h"
#include "io/files.h"
#include "io/progress.h"
#include "run/checkpoint.h"
#include "run/outputs.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace fs = std::filesystem;

namespace {

constexpr const char* kRunFormat = "diverse.run";
constexpr int kRunVersion = 1;

// Everything a run needs that is rebuilt from run.json on resume.
struct RunSetup {
  std::unique_ptr<TaskEvaluator> evaluator;
  DistanceSpec distance;
  bool vary_shape = false;
  DiversityOptions options;
  double strength = 1.0;  // Task::strength
  MotionBounds bounds;
  ParameterSet m0;  // M0's parameters, with its shape (scale 1) when shape varies
  std::string task_path;
  std::string task_text;
};

RunSetup make_setup(const std::string& task_path, const std::string& metric_name,
                    double shape_weight, bool vary_shape, const DiversityOptions& options,
                    double strength, const MotionBounds& bounds) {
  RunSetup setup;
  setup.task_path = fs::absolute(task_path).lexically_normal().string();
  setup.task_text = read_file(setup.task_path);
  Task task = load_task(setup.task_path);
  if (!(strength >= kMinStrength && strength <= kMaxStrength))
    throw UserError("--strength: expected a number in [0.1, 10], got " + std::to_string(strength));
  task.strength = strength;
  setup.strength = strength;
  setup.bounds = bounds;
  const std::string metric = metric_name.empty() ? task.metric : metric_name;
  setup.distance =
      parse_distance(metric, shape_weight, metric_name.empty() ? task.file + ": metric" : "--metric");
  setup.vary_shape = vary_shape;
  if (setup.distance.uses_shape() && !vary_shape)
    throw UserError("--metric: the " + to_string(setup.distance) +
                    " metric needs the shape parameters (--vary shape)");
  // Before any work: a character without [shape] parameters cannot vary its shape.
  if (vary_shape) require_shape(*task.character_spec);
  setup.options = options;
  if (setup.options.variations == 0) setup.options.variations = task.variations;
  if (setup.options.sigma0 == 0.0) setup.options.sigma0 = task.diversity.sigma0;
  if (setup.options.max_generations == 0)
    setup.options.max_generations = task.diversity.generations;
  if (!fs::exists(task.m0))
    throw UserError(task.file + ": m0: " + task.m0 +
                    " does not exist (create it with `diverse seed-motion " + task.name + "`)");
  setup.evaluator = std::make_unique<TaskEvaluator>(std::move(task));
  setup.m0 = setup.evaluator->load_parameters(setup.evaluator->task().m0);
  if (vary_shape) setup.m0 = setup.evaluator->with_shape(setup.m0, setup.evaluator->shapes().identity());
  return setup;
}

nlohmann::json run_json(const RunSetup& setup) {
  nlohmann::json j = {{"format", kRunFormat},
                      {"version", kRunVersion},
                      {"diverse_version", DIVERSE_VERSION},
                      {"task_file", setup.task_path},
                      {"task_text", setup.task_text},
                      {"metric", to_string(setup.distance)},
                      {"vary", vary_json(setup.vary_shape)},
                      {"options", to_json(setup.options)},
                      {"strength", setup.strength},
                      {"bounds", to_json(setup.bounds)}};
  if (setup.distance.combined()) j["shape_weight"] = setup.distance.shape_weight;
  return j;
}

// "vary" of run.json (absent in runs from before shapes could vary: control only).
bool read_vary_shape(const nlohmann::json& run, const std::string& where) {
  if (!run.contains("vary")) return false;
  const nlohmann::json& vary = run["vary"];
  if (vary == vary_json(false)) return false;
  if (vary == vary_json(true)) return true;
  throw_field_error(where, "vary", "expected [\"control\"] or [\"control\", \"shape\"]");
}

int resolve_threads(int threads, const Cluster* cluster) {
  if (threads < 0) throw UserError("--threads: expected an integer >= 0 (0 = one per core)");
  if (threads > 0) return threads;
  return cluster ? cluster->default_threads() : ThreadPool::hardware_threads();
}

// What a worker rank needs to build the same problem as rank 0 (serve_run reads it).
std::string cluster_setup(const RunSetup& setup) {
  const Eigen::VectorXd m0 = setup.m0.normalized();
  nlohmann::json j = {{"diverse_version", DIVERSE_VERSION},
                      {"task_file", setup.task_path},
                      {"task_text", setup.task_text},
                      {"metric", to_string(setup.distance)},
                      {"shape_weight", setup.distance.shape_weight},
                      {"vary_shape", setup.vary_shape},
                      {"strength", setup.strength},
                      {"bounds", to_json(setup.bounds)},
                      {"reference", std::vector<double>(m0.data(), m0.data() + m0.size())}};
  return j.dump();
}

// How an interrupted run continues: "`diverse resume DIR` continues from ...".
std::string resume_hint(const fs::path& dir, long long generation) {
  return "`diverse resume " + dir.string() + "` continues from " +
         (generation >= 0 ? "the last checkpoint (generation " + std::to_string(generation) + ")"
                          : std::string("the start (run.json holds the settings)"));
}

// The line rank 0 prints when mpirun stops it (a worker died, or the job was interrupted).
std::string stopped_line(const fs::path& dir, long long generation) {
  return "diverse: error: the run was stopped by mpirun (a rank ended, e.g. killed or its "
         "node lost, or the job was interrupted; mpirun names which); " +
         resume_hint(dir, generation);
}

// A failure of another rank, with how to continue the run.
[[noreturn]] void rethrow_resumable(const ClusterError& e, const fs::path& dir, long long generation) {
  throw ClusterError(std::string(e.what()) + "; " + resume_hint(dir, generation));
}

// summary.json's timing.messages: this session's traffic between the ranks.
nlohmann::json messages_json(const Cluster::Traffic& t) {
  const double n = t.tasks > 0 ? static_cast<double>(t.tasks) : 1.0;
  std::vector<double> ms = t.compute_ms;
  std::sort(ms.begin(), ms.end());
  auto quantile = [&](double q) {
    return ms.empty() ? 0.0 : ms[static_cast<std::size_t>(q * static_cast<double>(ms.size() - 1) + 0.5)];
  };
  return {{"remote_evaluations", t.tasks},
          {"task_bytes_per_evaluation", static_cast<double>(t.task_bytes) / n},
          {"result_bytes_per_evaluation", static_cast<double>(t.result_bytes) / n},
          {"round_trip_ms_per_evaluation", 1e3 * t.round_trip_seconds / n},
          {"remote_rollout_ms", {{"mean", 1e3 * t.compute_seconds / n},
                                 {"p10", quantile(0.1)}, {"p50", quantile(0.5)},
                                 {"p90", quantile(0.9)}, {"max", quantile(1.0)}}},
          {"overhead_us_per_evaluation", 1e6 * (t.round_trip_seconds - t.compute_seconds) / n}};
}

// One process: a batch on the thread pool, as the optimizer runs it by default, with
// every rollout's CPU time (its thread's, so time spent descheduled by other jobs does
// not count) and the batch sizes kept for summary.json's timing.rollouts: what
// scripts/scaling-model.py models many ranks from.
class TimedPoolEvaluator : public BatchEvaluator {
 public:
  TimedPoolEvaluator(const DiversityProblem& problem, ThreadPool& pool) : problem_(problem), pool_(pool) {}

  std::vector<std::shared_ptr<const Outcome>> evaluate(const std::vector<Eigen::VectorXd>& xs) override {
    std::vector<std::shared_ptr<const Outcome>> outcomes(xs.size());
    std::vector<double> ms(xs.size());
    pool_.parallel_for(xs.size(), [&](std::size_t k, int worker) {
      const double t0 = thread_cpu_seconds();
      outcomes[k] = problem_.evaluate(xs[k], worker);
      ms[k] = 1e3 * (thread_cpu_seconds() - t0);
    });
    cpu_ms_.insert(cpu_ms_.end(), ms.begin(), ms.end());
    batch_sizes_.push_back(static_cast<long long>(xs.size()));
    return outcomes;
  }

  // {"count", "cpu_ms": {"mean", "deciles": [p0, p10, ..., p100]}, "batches", "batch_size":
  // {"min", "max", "mean"}}; null before any batch.
  nlohmann::json to_json() const {
    if (cpu_ms_.empty()) return nullptr;
    std::vector<double> sorted = cpu_ms_;
    std::sort(sorted.begin(), sorted.end());
    std::vector<double> deciles;
    for (int q = 0; q <= 10; ++q)
      deciles.push_back(sorted[static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1) / 10.0 + 0.5)]);
    double sum = 0;
    for (double v : sorted) sum += v;
    long long total = 0;
    for (long long b : batch_sizes_) total += b;
    return {{"count", sorted.size()},
            {"cpu_ms", {{"mean", sum / static_cast<double>(sorted.size())}, {"deciles", deciles}}},
            {"batches", batch_sizes_.size()},
            {"batch_size", {{"min", *std::min_element(batch_sizes_.begin(), batch_sizes_.end())},
                            {"max", *std::max_element(batch_sizes_.begin(), batch_sizes_.end())},
                            {"mean", static_cast<double>(total) / static_cast<double>(batch_sizes_.size())}}}};
  }

 private:
  static double thread_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  }

  const DiversityProblem& problem_;
  ThreadPool& pool_;
  std::vector<double> cpu_ms_;
  std::vector<long long> batch_sizes_;
};

// Rank 0 of several: workers get the settings; batches go over every rank.
// `optimized` is the problem the optimizer runs on (`problem`, unless RunHooks wrap it).
std::unique_ptr<BatchEvaluator> cluster_evaluator(Cluster* cluster, const RunSetup& setup,
                                                  const MotionProblem& problem,
                                                  const DiversityProblem& optimized, ThreadPool& pool) {
  if (!cluster) return std::make_unique<TimedPoolEvaluator>(optimized, pool);
  cluster->start_workers(cluster_setup(setup));
  return cluster->evaluator(problem, pool, &MotionProblem::decode);
}

// The optimization loop shared by start and resume: steps, checkpoints, progress, and
// the outputs at the end.
void drive(const fs::path& dir, const RunSetup& setup, const MotionProblem& problem,
           DiversityOptimizer& optimizer, ThreadPool& pool, double wall_before,
           double checkpoint_seconds, bool quiet, bool render, Cluster* cluster,
           const BatchEvaluator* batch, const RunHooks& hooks) {
  const auto started = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return wall_before +
           std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  };
  long long saved_generation = -1;  // the generation of the last checkpoint written here
  auto write_checkpoint = [&] {
    try {
      write_json_atomic(dir / "checkpoint.json",
                        run_checkpoint_json(elapsed(), setup.vary_shape, optimizer));
    } catch (const UserError& e) {
      // A full disk or a vanished directory: the previous checkpoint is untouched (the
      // write went to a temporary), so the run can go on from it once the cause is gone.
      throw UserError(std::string(e.what()) + "; " +
                      (saved_generation >= 0 || fs::exists(dir / "checkpoint.json")
                           ? "the last checkpoint" +
                                 (saved_generation >= 0 ? " (generation " + std::to_string(saved_generation) + ")"
                                                        : std::string()) +
                                 " is intact: `diverse resume " + dir.string() + "` continues from it"
                           : std::string("no checkpoint was written")));
    }
    saved_generation = optimizer.generation();
    if (cluster) cluster->set_stop_message(stopped_line(dir, saved_generation));
  };

  std::FILE* sink = quiet ? nullptr : stderr;
  std::unique_ptr<ProgressReporter> progress;
  if (sink) {
    progress = std::make_unique<ProgressReporter>(sink, setup.options.max_generations);
    const int n = setup.options.variations;
    optimizer.set_callback(
        [&progress, n](const DiversityRecord& record) { progress->on_record(record, n); });
  }

  write_checkpoint();
  auto last = std::chrono::steady_clock::now();
  try {
    while (!optimizer.done()) {
      optimizer.step();
      if (hooks.on_generation && !hooks.on_generation(optimizer)) {
        // Stopped by the caller: resumable like an interrupted run.
        write_checkpoint();
        if (progress) progress->finish("stopped after generation " + std::to_string(optimizer.generation()) +
                                       "; " + resume_hint(dir, optimizer.generation()));
        return;
      }
      const auto now = std::chrono::steady_clock::now();
      if (std::chrono::duration<double>(now - last).count() >= checkpoint_seconds) {
        write_checkpoint();
        last = now;
      }
    }
  } catch (const ClusterError& e) {
    rethrow_resumable(e, dir, saved_generation);
  }
  write_checkpoint();
  if (progress)
    progress->finish("optimization ended (" + std::string(to_string(optimizer.stop_reason())) +
                     ") after " + std::to_string(optimizer.generation()) + " generations, " +
                     std::to_string(optimizer.evaluations()) + " evaluations, " +
                     std::to_string(optimizer.confirmations()) + " half-timestep checks, " +
                     std::to_string(steps_of(optimizer.ledger())) + " simulation steps");

  RunOutputs outputs{dir, *setup.evaluator, problem, optimizer, pool};
  outputs.wall_seconds = elapsed();
  outputs.render = render;
  outputs.ranks = cluster ? cluster->size() : 1;
  if (cluster) outputs.messages = messages_json(cluster->traffic());
  if (const auto* timed = dynamic_cast<const TimedPoolEvaluator*>(batch)) outputs.rollouts = timed->to_json();
  outputs.custom = hooks.custom;
  write_run_outputs(outputs);
  if (sink) std::fprintf(sink, "results in %s (summary.json, motions/, filmstrip.png)\n",
                         dir.string().c_str());
}

bool holds_run(const fs::path& dir) {
  return fs::exists(dir / "run.json") || fs::exists(dir / "checkpoint.json") ||
         fs::exists(dir / "summary.json");
}

}  // namespace

nlohmann::json without_timing(nlohmann::json summary) {
  summary.erase("timing");
  return summary;
}

void start_run(const RunRequest& request) {
  const int threads = resolve_threads(request.threads, request.cluster);
  RunSetup setup = make_setup(resolve_task_path(request.task), request.metric, request.shape_weight,
                              request.vary_shape, request.options, request.strength, request.bounds);
  try {
    validate(setup.options);  // after the task's N has filled in variations = 0
  } catch (const std::invalid_argument& e) {
    throw UserError(e.what());
  }

  if (holds_run(request.out)) {
    if (!request.force)
      throw UserError(request.out.string() +
                      ": already holds a run (use --force to replace it, or `diverse resume " +
                      request.out.string() + "` to continue it)");
    for (const char* name : {"run.json", "checkpoint.json", "summary.json", "log.jsonl",
                             "filmstrip.png", "motions", "model", "paths"})
      fs::remove_all(request.out / name);
  }
  if (request.hooks.wrap_problem && request.cluster)
    throw std::logic_error("start_run: a wrapped problem runs in one process");
  ensure_writable_directory(request.out);
  nlohmann::json settings = run_json(setup);
  if (!request.hooks.custom.is_null()) settings["custom"] = request.hooks.custom;
  write_json_atomic(request.out / "run.json", settings);

  if (request.cluster) request.cluster->set_stop_message(stopped_line(request.out, -1));

  ThreadPool pool(threads);
  const MotionProblem problem(*setup.evaluator, setup.distance, setup.m0.normalized(), pool.size(),
                              setup.vary_shape, setup.bounds);
  const std::unique_ptr<DiversityProblem> wrapped =
      request.hooks.wrap_problem ? request.hooks.wrap_problem(problem) : nullptr;
  const DiversityProblem& optimized = wrapped ? *wrapped : static_cast<const DiversityProblem&>(problem);
  std::unique_ptr<BatchEvaluator> batch;
  std::unique_ptr<DiversityOptimizer> started;
  try {
    batch = cluster_evaluator(request.cluster, setup, problem, optimized, pool);
    started = std::make_unique<DiversityOptimizer>(optimized, setup.options, pool, batch.get());
  } catch (const ClusterError& e) {
    rethrow_resumable(e, request.out, -1);
  }
  DiversityOptimizer& optimizer = *started;
  if (!request.quiet && optimizer.current_score().constraint[0] > 0) {
    // Most often a strength model: the input motion was found for the character at 1.
    char strength[32], c0[32];
    std::snprintf(strength, sizeof strength, "%g", setup.strength);
    std::snprintf(c0, sizeof c0, "%g", optimizer.current_score().constraint[0]);
    const bool strong = setup.strength != 1.0;
    std::fprintf(stderr,
                 "diverse: note: the input motion M0 does not meet the task%s%s (C = %s); the "
                 "variations start from it and must first find the task. To find an input motion "
                 "for this character: `diverse seed-motion %s%s%s --start %s --out FILE`, then name "
                 "FILE as m0 in a copy of the task file\n",
                 strong ? " at strength " : "", strong ? strength : "", c0,
                 setup.evaluator->task().name.c_str(), strong ? " --strength " : "", strong ? strength : "",
                 setup.evaluator->task().m0.c_str());
  }
  drive(request.out, setup, problem, optimizer, pool, 0.0, request.checkpoint_seconds,
        request.quiet, request.render, request.cluster, batch.get(), request.hooks);
}

void resume_run(const fs::path& dir, int threads_arg, bool quiet, double checkpoint_seconds,
                bool render, Cluster* cluster, const RunHooks& hooks) {
  const int threads = resolve_threads(threads_arg, cluster);
  if (!fs::is_directory(dir)) throw UserError(dir.string() + ": not a directory");
  if (!fs::exists(dir / "run.json"))
    throw UserError(dir.string() + ": not a run directory (no run.json; start one with `diverse run`)");
  const nlohmann::json run = read_json(dir / "run.json");
  const std::string where = (dir / "run.json").string();
  if (!run.is_object() || !run.contains("format") || run["format"] != kRunFormat)
    throw UserError(where + ": format: expected \"" + kRunFormat + "\"");
  if (run.contains("custom") && !hooks.wrap_problem)
    throw UserError(where + ": custom: the run's " + run["custom"].dump() +
                    " is a program's own code; resume it from that program (Python: diverse.resume)");
  DiversityOptions options;
  try {
    options = diversity_options_from_json(run.at("options"));
    validate(options);
  } catch (const UserError& e) {
    throw UserError(where + ": options." + e.what());
  } catch (const std::invalid_argument& e) {
    throw UserError(where + ": options: " + e.what());
  } catch (const nlohmann::json::exception& e) {
    throw UserError(where + ": options: expected the settings `diverse run` writes (" + e.what() + ")");
  }
  RunSetup setup;
  try {
    const std::string task_file = run.at("task_file").get<std::string>();
    const std::string task_text = run.at("task_text").get<std::string>();
    if (!fs::exists(task_file))
      throw UserError(where + ": task_file: " + task_file + " no longer exists");
    if (read_file(task_file) != task_text)
      throw UserError(task_file + ": changed since the run started; a resumed run must use the same task");
    // Runs from before strength and bounds existed have neither: strength 1, no bounds.
    const nlohmann::json& strength = run.contains("strength") ? run["strength"] : nlohmann::json(1.0);
    if (!strength.is_number() || !(strength.get<double>() >= kMinStrength && strength.get<double>() <= kMaxStrength))
      throw_field_error(where, "strength", "expected a number in [0.1, 10]");
    setup = make_setup(task_file, run.at("metric").get<std::string>(),
                       run.value("shape_weight", kDefaultShapeWeight), read_vary_shape(run, where),
                       options, strength.get<double>(),
                       motion_bounds_from_json(run.contains("bounds") ? run["bounds"] : nlohmann::json(), where));
  } catch (const nlohmann::json::exception& e) {
    throw UserError(where + ": expected the settings `diverse run` writes (" + e.what() + ")");
  }

  ThreadPool pool(threads);
  const MotionProblem problem(*setup.evaluator, setup.distance, setup.m0.normalized(), pool.size(),
                              setup.vary_shape, setup.bounds);
  const std::unique_ptr<DiversityProblem> wrapped = hooks.wrap_problem ? hooks.wrap_problem(problem) : nullptr;
  const DiversityProblem& optimized = wrapped ? *wrapped : static_cast<const DiversityProblem&>(problem);
  // What a kill in the middle of a write left (the files themselves are whole: io/files.h).
  for (const char* sub : {"", "motions", "model", "paths"}) remove_stale_temporaries(dir / sub);
  double wall_before = 0.0;
  std::unique_ptr<DiversityOptimizer> optimizer;
  if (fs::exists(dir / "checkpoint.json")) {
    const nlohmann::json state = read_run_checkpoint(dir / "checkpoint.json", setup.vary_shape, &wall_before);
    const long long generation = state.value("generation", -1LL);
    if (cluster) cluster->set_stop_message(stopped_line(dir, generation));
    std::unique_ptr<BatchEvaluator> batch;
    try {
      batch = cluster_evaluator(cluster, setup, problem, optimized, pool);
      optimizer = restore_optimizer(optimized, state, pool, dir / "checkpoint.json", batch.get());
    } catch (const ClusterError& e) {
      rethrow_resumable(e, dir, generation);
    }
    drive(dir, setup, problem, *optimizer, pool, wall_before, checkpoint_seconds, quiet, render, cluster,
          batch.get(), hooks);
  } else {
    // Stopped between writing run.json and its first checkpoint: run.json holds every
    // setting, so the run starts again from generation 0 (the same run, by determinism).
    if (cluster) cluster->set_stop_message(stopped_line(dir, -1));
    std::unique_ptr<BatchEvaluator> batch;
    try {
      batch = cluster_evaluator(cluster, setup, problem, optimized, pool);
      optimizer = std::make_unique<DiversityOptimizer>(optimized, setup.options, pool, batch.get());
    } catch (const ClusterError& e) {
      rethrow_resumable(e, dir, -1);
    }
    drive(dir, setup, problem, *optimizer, pool, wall_before, checkpoint_seconds, quiet, render, cluster,
          batch.get(), hooks);
  }
}

void serve_run(Cluster& cluster, int threads_arg) {
  std::string text;
  if (!cluster.receive_setup(&text)) return;  // rank 0 ended before the run began
  std::unique_ptr<MotionProblem> problem;
  RunSetup setup;
  int threads = 1;
  try {
    threads = resolve_threads(threads_arg, &cluster);
    const nlohmann::json j = nlohmann::json::parse(text);
    const std::string version = j.at("diverse_version").get<std::string>();
    if (version != DIVERSE_VERSION)
      throw UserError("runs diverse " + std::string(DIVERSE_VERSION) + ", rank 0 runs " + version +
                      "; every rank must run the same build");
    const std::string task_file = j.at("task_file").get<std::string>();
    if (!fs::exists(task_file))
      throw UserError(task_file + ": does not exist on this node (every node needs the task's "
                      "files at the same path as rank 0)");
    if (read_file(task_file) != j.at("task_text").get<std::string>())
      throw UserError(task_file + ": differs from rank 0's copy; every node needs the same task files");
    setup = make_setup(task_file, j.at("metric").get<std::string>(), j.at("shape_weight").get<double>(),
                       j.at("vary_shape").get<bool>(), DiversityOptions{}, j.at("strength").get<double>(),
                       motion_bounds_from_json(j.at("bounds"), "rank 0's settings"));
    const std::vector<double> reference = j.at("reference").get<std::vector<double>>();
    const Eigen::VectorXd m0 = setup.m0.normalized();
    if (static_cast<Eigen::Index>(reference.size()) != m0.size() ||
        !std::equal(reference.begin(), reference.end(), m0.data()))
      throw UserError(setup.evaluator->task().m0 +
                      ": differs from rank 0's input motion; every node needs the same files");
    problem = std::make_unique<MotionProblem>(*setup.evaluator, setup.distance, m0, threads,
                                              setup.vary_shape, setup.bounds);
  } catch (const std::exception& e) {
    cluster.refuse_setup(e.what());
    return;
  }
  cluster.serve(*problem, threads, &MotionProblem::encode);
}

}  // namespace diverse
