// `diverse seed-motion TASK`: finds the task's input motion M0 by CMA-ES on the
// constraint penalty, starting from the hand-authored jump the task names
// ([seed] base), with continuation on the scene object's height where the task asks for
// it (src/task/seed_motion.h), and writes the parameters to the task's m0 file.
// With `--robust`, a candidate that meets the task counts only if it also holds under the
// robustness suite's small part (robust/robustness.h, robust_sample_suite(): what
// `diverse run --robust` asks of its samples); one that does not gets
// robust_failure_penalty() added to its C, so the m0 file only ever receives a motion
// that holds it. `--robustness-check` instead measures a motion (by default the task's
// M0): its C at the task's timestep and with it halved, how many random perturbations of
// its normalized parameters still meet the task, and with `--robust` whether it holds the
// suite's part.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <string>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "core/thread_pool.h"
#include "eval/motion_problem.h"
#include "io/files.h"
#include "robust/robustness.h"
#include "task/evaluate.h"
#include "task/seed_motion.h"

namespace diverse::cli {
namespace {

struct SeedArgs {
  std::string task;
  std::string start;
  std::string out;
  int threads = 1;
  int generations = 0;
  double sigma = 0;
  int perturbations = 0;
  double perturbation_sigma = 0.02;
  int pushes = 0;
  double push_speed = 0.3;
  int selection_samples = 32;
  std::string objective = "mean";
  double min_flight_rotation_deg = 0;
  bool robustness_check = false;
  std::vector<double> check_sigmas{0.02, 0.05};
  int check_samples = 32;
  bool convergence = false;
  int from_stage = 0;
  double strength = 1.0;
  bool robust = false;
};

// The options that change what is searched for (not how long or from where), as they
// must be given again to go on from a partial result or a stage: strength, flight
// rotation, the robustness term and --robust.
std::string searched_options(const SeedArgs& args) {
  auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof(text), "%g", v);
    return std::string(text);
  };
  std::string options;
  if (args.strength != 1.0) options += " --strength " + number(args.strength);
  if (args.min_flight_rotation_deg > 0) options += " --min-flight-rotation " + number(args.min_flight_rotation_deg);
  if (args.perturbations > 0) {
    options += " --perturbations " + std::to_string(args.perturbations) + " --perturbation-sigma " +
               number(args.perturbation_sigma);
  }
  if (args.pushes > 0) {
    options += " --pushes " + std::to_string(args.pushes);
    if (args.push_speed != 0.3) options += " --push-speed " + number(args.push_speed);
  }
  if (args.perturbations > 0 || args.pushes > 0) {
    if (args.selection_samples != 32) options += " --selection-samples " + std::to_string(args.selection_samples);
    if (args.objective != "mean") options += " --objective " + args.objective;
  }
  if (args.robust) options += " --robust";
  return options;
}

// The task at the strength asked for (Task::strength).
Task task_at_strength(const SeedArgs& args) {
  Task task = load_task(resolve_task_path(args.task));
  task.strength = args.strength;
  return task;
}

// "tasks/x.m0.json" -> "tasks/x"; "a/b.json" -> "a/b".
std::string output_stem(const std::string& path) {
  for (const std::string suffix : {".m0.json", ".json"}) {
    if (path.size() > suffix.size() && path.compare(path.size() - suffix.size(), suffix.size(), suffix) == 0)
      return path.substr(0, path.size() - suffix.size());
  }
  return path;
}

// The robustness suite's part (--robust) as "2 parameter perturbations at sigma 0.02 and 2
// pushes of 0.3 m/s in the landing".
std::string describe_part(const RobustnessSuite& suite, const std::vector<PerturbedRollout>& rollouts) {
  std::string phase;
  for (const PerturbedRollout& r : rollouts) {
    if (r.kind != PerturbationKind::kPush) continue;
    phase = r.phase == "landing" ? " in the landing" : r.phase == "steps" ? " in the evaluated steps" : "";
    break;
  }
  char text[200];
  std::snprintf(text, sizeof text, "%d parameter perturbations at sigma %g and %d pushes of %g m/s%s",
                suite.parameter_samples, suite.sigma, suite.push_samples, suite.push_speed, phase.c_str());
  return text;
}

// --robustness-check --robust: whether the motion holds the suite's part, as the search
// and `diverse run --robust` judge it (check_suite), with every rollout's outcome.
void robust_check(const TaskEvaluator& ev, const ParameterSet& p, int threads) {
  const RobustnessSuite suite = robust_sample_suite();
  const SuiteVerdict verdict = check_suite(ev, p, suite);
  ThreadPool pool(threads);
  const MotionRobustness all = run_robustness_suite(ev, {MotionUnderTest{"M0", 0, p}}, suite, pool).front();
  const int needed = static_cast<int>(std::ceil(suite.required_share * all.count() - 1e-9));
  std::printf("  the robustness suite's part (--robust: %s): %s, %d of %d perturbed rollouts meet the task "
              "(params %d/%d, pushes %d/%d; %d needed)\n",
              describe_part(suite, all.rollouts).c_str(), verdict.holds ? "holds" : "does not hold", all.held(),
              all.count(), all.held(PerturbationKind::kParameters), all.count(PerturbationKind::kParameters),
              all.held(PerturbationKind::kPush), all.count(PerturbationKind::kPush), needed);
}

void check(const SeedArgs& args) {
  const Task task = task_at_strength(args);
  const TaskEvaluator ev(task);
  const std::string path = args.start.empty() ? task.m0 : args.start;
  const ParameterSet p = ev.load_parameters(path);
  if (args.convergence && task.walk.enabled)
    throw UserError("--convergence: compares where a jump first touches down; " + task.file + " is a walk");
  const RobustnessReport r =
      measure_robustness(task, p, args.check_sigmas, args.check_samples, args.threads, args.convergence);
  std::printf("%s: %s\n", task.name.c_str(), path.c_str());
  std::printf("  C = %.6g at the task's timestep, %.6g with it halved\n", r.constraint,
              r.constraint_fine);
  if (std::isnan(r.landing_shift)) {
    std::printf("  landing spots at the two timesteps: not compared (a fall)\n");
  } else {
    std::printf("  landing spots at the two timesteps differ by %.3f m (input motions: at most %.2f m)\n",
                r.landing_shift, kTimestepAgreement);
  }
  if (args.convergence) {
    std::printf("  first touch-down at the task's timestep, half and a quarter of it: x = %.3f, %.3f, %.3f m "
                "(C = %.6g at a quarter)\n",
                r.touchdown_x[0], r.touchdown_x[1], r.touchdown_x[2], r.constraint_quarter);
  }
  for (const RobustnessReport::Level& l : r.levels) {
    std::printf("  sigma %g: %d of %d perturbations meet the task (%.0f %%)\n", l.sigma, l.met,
                l.samples, 100 * l.fraction());
    if (!args.convergence) continue;
    const TimestepConvergence& v = l.convergence;
    if (v.compared == 0) {
      std::printf("    touch-downs at three timesteps: none of them touched down at all three\n");
    } else {
      std::printf("    touch-downs at the step and half of it %.3f m apart on average (at most %.3f), at half and "
                  "a quarter %.3f m (at most %.3f); %d of %d compared\n",
                  v.half_mean, v.half_max, v.quarter_mean, v.quarter_max, v.compared, l.samples);
      std::printf("    peak heights (set at take-off) %.4f m apart on average at the step and half of it, %.4f m at "
                  "half and a quarter\n",
                  v.peak_half_mean, v.peak_quarter_mean);
    }
  }
  if (args.robust) robust_check(ev, p, args.threads);
}

void run(const SeedArgs& args) {
  if (args.objective != "mean" && args.objective != "share")
    throw UserError("--objective: expected mean or share, got '" + args.objective + "'");
  if (args.robustness_check) return check(args);
  if (args.convergence)
    throw UserError("--convergence: only with --robustness-check (it measures a motion, it does not search)");
  const Task task = task_at_strength(args);
  const TaskEvaluator ev(task);
  const std::string start_path = args.start.empty() ? task.seed.base : args.start;
  if (start_path.empty()) {
    throw UserError(task.file + ": seed.base: expected the starting parameters (missing)");
  }
  const ParameterSet start = ev.load_parameters(start_path);
  SeedOptions options;
  options.threads = args.threads;
  options.generations = args.generations;
  options.sigma = args.sigma;
  options.perturbations = args.perturbations;
  options.perturbation_sigma = args.perturbation_sigma;
  options.pushes = args.pushes;
  options.push_speed = args.push_speed;
  options.selection_samples = args.selection_samples;
  options.objective = args.objective == "share" ? SeedObjective::kShare : SeedObjective::kMeanC;
  options.min_flight_rotation = args.min_flight_rotation_deg * M_PI / 180;
  options.first_stage = args.from_stage;
  if (args.robust) {
    // What `diverse run --robust` asks of its samples, with the same penalty for a miss.
    options.requirement.name = "robust part";
    options.requirement.penalty = robust_failure_penalty(task);
    options.requirement.check = [&ev](const ParameterSet& p) {
      const SuiteVerdict v = check_suite(ev, p, robust_sample_suite());
      // The unperturbed rollout that gives the push moments, the perturbed ones and their
      // half-timestep checks.
      return SeedRequirement::Verdict{v.holds, 1LL + v.rollouts + v.half_timestep_checks};
    };
  }
  options.log = [](const std::string& line) { std::printf("%s\n", line.c_str()); std::fflush(stdout); };
  const std::string m0_path = args.out.empty() ? task.m0 : args.out;
  const std::string stem = output_stem(m0_path);
  // Every continuation stage's result is kept, so a long search that is stopped goes on
  // with --start <stem>.stage<k>.json --from-stage <k+1>.
  options.on_stage = [&](int stage, double value, const ParameterSet& p, double constraint) {
    nlohmann::json j;
    j["task"] = task.name;
    j["stage"] = stage;
    j["stage_value"] = value;
    j["constraint"] = constraint;
    j["continue_with"] = "diverse seed-motion " + args.task + " --start " + stem + ".stage" +
                         std::to_string(stage) + ".json" + searched_options(args) + " --from-stage " +
                         std::to_string(stage + 1);
    j["parameters"] = p.to_json();
    const std::string path = stem + ".stage" + std::to_string(stage) + ".json";
    write_json_atomic(path, j);
    std::printf("stage %d ends with C=%.6g -> %s\n", stage, constraint, path.c_str());
    std::fflush(stdout);
  };
  const SeedResult r = seed_motion(task, start, options);
  // The task's m0 file only ever holds a motion that meets the task (with --robust, that
  // also holds the robustness suite's part: its C includes the penalty otherwise); a
  // search that falls short writes its best attempt beside it, to continue from with
  // --start. With perturbations, a robust near miss that ranks above the motion that
  // meets the task is written there too: it is the better place to continue from.
  const bool met = r.constraint == 0 && !r.requirement_failed;
  const std::string partial_path = stem + ".partial.json";
  // The command as the user gave it: --start only when it was given (the task's [seed]
  // base otherwise, named relative to the task file).
  std::string command = "diverse seed-motion " + args.task;
  if (!args.start.empty()) command += " --start " + args.start;
  if (args.generations > 0) command += " --generations " + std::to_string(args.generations);
  if (args.sigma > 0) {
    char sigma[32];
    std::snprintf(sigma, sizeof(sigma), "%g", args.sigma);
    command += std::string(" --sigma ") + sigma;
  }
  command += searched_options(args);
  if (args.from_stage > 0) command += " --from-stage " + std::to_string(args.from_stage);
  command += " (" + std::to_string(r.evaluations) + " rollouts)";
  auto write = [&](const std::string& path, const ParameterSet& p, double constraint) {
    nlohmann::json j;
    j["task"] = task.name;
    j["constraint"] = constraint;
    j["margin"] = r.margin;
    if (args.perturbations > 0 || args.pushes > 0) j["robustness"] = r.robustness;
    if (!r.selected.empty())
      j["selection"] = {{"candidates", r.selection_candidates}, {"chosen", r.selected},
                        {"samples", args.selection_samples}};
    j["found_by"] = command;
    j["parameters"] = p.to_json();
    write_json_atomic(path, j);
  };
  const std::string out = met ? m0_path : partial_path;
  write(out, r.parameters, r.constraint);
  std::string robust;
  if (args.robust) {
    // Judged only on a result that meets the task at both timesteps.
    robust = std::string(" robust=") + (r.requirement_failed ? "fails" : met ? "holds" : "n/a") + " (" +
             std::to_string(r.requirement_held) + " of " + std::to_string(r.requirement_checks) +
             " candidates that met the task held the suite's part)";
  }
  std::printf("C=%.6g margin=%.3f robustness=%.3f fell=%d evaluations=%lld seconds=%.1f%s -> %s\n",
              r.constraint, r.margin, r.robustness, r.fell ? 1 : 0, r.evaluations, r.seconds, robust.c_str(),
              out.c_str());
  if (met && !r.lowest_mean_meets && (args.perturbations > 0 || args.pushes > 0)) {
    nlohmann::json j;
    j["task"] = task.name;
    j["objective"] = r.lowest_mean_f;
    j["found_by"] = command;
    j["parameters"] = r.lowest_mean.to_json();
    write_json_atomic(partial_path, j);
    std::printf("a more robust candidate that does not meet the task yet (mean C = %.6g) -> %s\n",
                r.lowest_mean_f, partial_path.c_str());
  }
  if (!met && r.requirement_failed)
    throw UserError(task.file + ": no motion meeting the task and holding the robustness suite's part (--robust) "
                    "was found (the best meets the task but not the part, C = " + std::to_string(r.constraint) +
                    "); continue with `diverse seed-motion " + args.task + " --start " + out +
                    searched_options(args) + "`");
  if (!met)
    throw UserError(task.file + ": no motion meeting the task was found (best C = " +
                    std::to_string(r.constraint) + "); continue with `diverse seed-motion " +
                    args.task + " --start " + out + searched_options(args) + "`");
}

void install(CLI::App& app) {
  auto args = std::make_shared<SeedArgs>();
  CLI::App* cmd = app.add_subcommand(
      "seed-motion", "Find a task's input motion M0 by CMA-ES on its constraint penalty");
  cmd->footer("Examples:\n"
              "  diverse seed-motion jump_forward --generations 100 --out m0.json\n"
              "  diverse seed-motion backflip --robustness-check --convergence");
  cmd->add_option("task", args->task, "Task name (tasks/<name>.toml) or task file")->required();
  cmd->add_option("--start", args->start, "Starting parameters (default: the task's seed.base)");
  cmd->add_option("--out", args->out, "Output file (default: the task's m0 file)");
  cmd->add_option("--strength", args->strength,
                  "Strength model: every joint's PD gains and torque limits times S (an input "
                  "motion for a stronger or weaker character; start it from the task's M0)")
      ->capture_default_str()
      ->check(number_in(kMinStrength, kMaxStrength));
  cmd->add_option("--threads", args->threads, "Worker threads")->check(integer_in(1, kMaxThreads));
  cmd->add_option("--generations", args->generations,
                  "CMA-ES generations per stage (default: the task's seed.generations)")
      ->check(integer_in(1, 100000));
  cmd->add_option("--sigma", args->sigma,
                  "Initial CMA-ES step, normalized (default: the task's seed.sigma)")
      ->check(number_in(1e-6, 1.0));
  cmd->add_option("--perturbations", args->perturbations,
                  "Robustness term: perturbed rollouts per candidate (0 = off)")
      ->check(integer_in(0, 1000));
  cmd->add_option("--perturbation-sigma", args->perturbation_sigma,
                  "Robustness term: their standard deviation, in normalized units")
      ->check(number_in(1e-6, 1.0));
  cmd->add_option("--pushes", args->pushes,
                  "Robustness term: pushed rollouts per candidate, drawn as the robustness suite "
                  "draws its pushes (0 = off; docs/guide/robustness.md)")
      ->check(integer_in(0, 1000));
  cmd->add_option("--push-speed", args->push_speed, "Robustness term: the pushes' change of the root's speed (m/s)")
      ->capture_default_str()
      ->check(number_in(1e-6, 10.0));
  cmd->add_option("--selection-samples", args->selection_samples,
                  "Robustness term: the result is chosen among the last stage's six best "
                  "candidates, the CMA-ES mean and the start by how many of this many further "
                  "perturbations meet the task (0 = the best candidate as scored)")
      ->capture_default_str()
      ->check(integer_in(0, 1000));
  cmd->add_option("--objective", args->objective,
                  "Robustness term: a candidate's objective over its rollouts, \"mean\" (the mean C) "
                  "or \"share\" (the share that misses the task, misses ranked by log(1 + C) / 100)")
      ->capture_default_str();
  cmd->add_option("--min-flight-rotation", args->min_flight_rotation_deg,
                  "Require this root rotation (degrees, backwards positive) between take-off and "
                  "touch-down while searching (0 = none)")
      ->check(number_in(0, 720));
  cmd->add_option("--from-stage", args->from_stage,
                  "Start at this continuation stage (0 = the first); every stage's result is "
                  "written to <m0 stem>.stage<k>.json to go on from")
      ->check(integer_in(0, 100));
  cmd->add_flag("--robust", args->robust,
                "A candidate meets the task only if it also holds under the robustness suite's "
                "small part, as `diverse run --robust` judges samples (2 parameter perturbations, "
                "2 pushes in the landing; 3 of 4 must hold); with --robustness-check, report "
                "whether the motion holds it (docs/guide/robustness.md)");
  cmd->add_flag("--robustness-check", args->robustness_check,
                "Measure a motion instead of searching (default: the task's M0, or --start)");
  cmd->add_option("--check-sigmas", args->check_sigmas,
                  "Robustness check: perturbation sizes, normalized (default 0.02 0.05); each size "
                  "gets the same perturbations whatever the others")
      ->check(number_in(1e-6, 1.0));
  cmd->add_flag("--convergence", args->convergence,
                "Robustness check of a jump: also simulate the motion and each perturbation at the "
                "task's timestep, half and a quarter of it, and say how far apart their first "
                "touch-downs are; a motion converged in the timestep comes down ever nearer one "
                "spot as the step shrinks (docs/guide/robustness.md)");
  cmd->add_option("--check-samples", args->check_samples,
                  "Robustness check: perturbations per size (default 32)")
      ->check(integer_in(1, 100000));
  cmd->callback([args] { run(*args); });
}

const bool registered = register_command(40, install);

}  // namespace
}  // namespace diverse::cli
