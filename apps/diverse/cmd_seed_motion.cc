// `diverse seed-motion TASK`: finds the task's input motion M0 by CMA-ES on the
// constraint penalty, starting from the hand-authored jump the task names
// ([seed] base), with continuation on the scene object's height where the task asks for
// it (src/task/seed_motion.h), and writes the parameters to the task's m0 file.
// `--robustness-check` instead measures a motion (by default the task's M0): its C at
// the task's timestep and with it halved, and how many random perturbations of its
// normalized parameters still meet the task.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <string>

#include "command.h"
#include "options.h"
#include "io/files.h"
#include "core/error.h"
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
  double min_flight_rotation_deg = 0;
  bool robustness_check = false;
  std::vector<double> check_sigmas{0.02, 0.05};
  int check_samples = 32;
  int from_stage = 0;
  double strength = 1.0;
};

// The options that change what is searched for (not how long or from where), as they
// must be given again to go on from a partial result or a stage: strength, flight
// rotation and the robustness term.
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

void check(const SeedArgs& args) {
  const Task task = task_at_strength(args);
  const TaskEvaluator ev(task);
  const std::string path = args.start.empty() ? task.m0 : args.start;
  const ParameterSet p = ev.load_parameters(path);
  const RobustnessReport r =
      measure_robustness(task, p, args.check_sigmas, args.check_samples, args.threads);
  std::printf("%s: %s\n", task.name.c_str(), path.c_str());
  std::printf("  C = %.6g at the task's timestep, %.6g with it halved\n", r.constraint,
              r.constraint_fine);
  if (std::isnan(r.landing_shift)) {
    std::printf("  landing spots at the two timesteps: not compared (a fall)\n");
  } else {
    std::printf("  landing spots at the two timesteps differ by %.3f m (input motions: at most %.2f m)\n",
                r.landing_shift, kTimestepAgreement);
  }
  for (const RobustnessReport::Level& l : r.levels) {
    std::printf("  sigma %g: %d of %d perturbations meet the task (%.0f %%)\n", l.sigma, l.met,
                l.samples, 100 * l.fraction());
  }
}

void run(const SeedArgs& args) {
  if (args.robustness_check) return check(args);
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
  options.min_flight_rotation = args.min_flight_rotation_deg * M_PI / 180;
  options.first_stage = args.from_stage;
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
  // The task's m0 file only ever holds a motion that meets the task; a search that falls
  // short writes its best attempt beside it, to continue from with --start. With
  // perturbations, a robust near miss that ranks above the motion that meets the task is
  // written there too: it is the better place to continue from.
  const bool met = r.constraint == 0;
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
    if (args.perturbations > 0) j["robustness"] = r.robustness;
    j["found_by"] = command;
    j["parameters"] = p.to_json();
    write_json_atomic(path, j);
  };
  const std::string out = met ? m0_path : partial_path;
  write(out, r.parameters, r.constraint);
  std::printf("C=%.6g margin=%.3f robustness=%.3f fell=%d evaluations=%lld seconds=%.1f -> %s\n",
              r.constraint, r.margin, r.robustness, r.fell ? 1 : 0, r.evaluations, r.seconds,
              out.c_str());
  if (met && !r.lowest_mean_meets && args.perturbations > 0) {
    nlohmann::json j;
    j["task"] = task.name;
    j["objective"] = r.lowest_mean_f;
    j["found_by"] = command;
    j["parameters"] = r.lowest_mean.to_json();
    write_json_atomic(partial_path, j);
    std::printf("a more robust candidate that does not meet the task yet (mean C = %.6g) -> %s\n",
                r.lowest_mean_f, partial_path.c_str());
  }
  if (!met)
    throw UserError(task.file + ": no motion meeting the task was found (best C = " +
                    std::to_string(r.constraint) + "); continue with `diverse seed-motion " +
                    args.task + " --start " + out + searched_options(args) + "`");
}

void install(CLI::App& app) {
  auto args = std::make_shared<SeedArgs>();
  CLI::App* cmd = app.add_subcommand(
      "seed-motion", "Find a task's input motion M0 by CMA-ES on its constraint penalty");
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
  cmd->add_option("--min-flight-rotation", args->min_flight_rotation_deg,
                  "Require this root rotation (degrees, backwards positive) between take-off and "
                  "touch-down while searching (0 = none)")
      ->check(number_in(0, 720));
  cmd->add_option("--from-stage", args->from_stage,
                  "Start at this continuation stage (0 = the first); every stage's result is "
                  "written to <m0 stem>.stage<k>.json to go on from")
      ->check(integer_in(0, 100));
  cmd->add_flag("--robustness-check", args->robustness_check,
                "Measure a motion instead of searching (default: the task's M0, or --start)");
  cmd->add_option("--check-sigmas", args->check_sigmas,
                  "Robustness check: perturbation sizes, normalized (default 0.02 0.05)")
      ->check(number_in(1e-6, 1.0));
  cmd->add_option("--check-samples", args->check_samples,
                  "Robustness check: perturbations per size (default 32)")
      ->check(integer_in(1, 100000));
  cmd->callback([args] { run(*args); });
}

const bool registered = register_command(40, install);

}  // namespace
}  // namespace diverse::cli
