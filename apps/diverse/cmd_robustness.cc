// `diverse robustness MOTION|RUN [--task FILE]`: the robustness suite (robust/robustness.h,
// docs/guide/robustness.md) on one motion or on every motion of a run: perturbed parameters,
// pushes to the root in ground phases, friction lower and higher, the timestep halved;
// per motion and kind, the share of perturbed rollouts that still meet the task.
//
//   diverse robustness runs/bf                      every motion M0..MN of a finished run;
//                                                   writes runs/bf/robustness.json
//   diverse robustness runs/bf/motions/m2.json      one motion of a run (its task, strength
//                                                   and shape as the run had them)
//   diverse robustness out/motion.json              a motion of `diverse simulate` (its
//                                                   task: --task, else tasks/<task>.toml)
//   diverse robustness --task tasks/backflip.toml   the task's input motion M0
//   diverse robustness P.json --task FILE           a parameter file of the task
//
// A motion of another task than --task, a file that is none of these: one line naming the
// file, the field and what was expected, exit code 2.
#include <CLI/CLI.hpp>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "core/thread_pool.h"
#include "finished/run_problem.h"
#include "finished/run_view.h"
#include "io/files.h"
#include "robust/robustness.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse::cli {
namespace {
namespace fs = std::filesystem;

struct RobustnessArgs {
  std::string target;
  std::string task;
  std::string out;
  double sigma = RobustnessSuite{}.sigma;
  int samples = RobustnessSuite{}.parameter_samples;
  double push = RobustnessSuite{}.push_speed;
  std::uint64_t seed = RobustnessSuite{}.seed;
  int threads = 0;
};

// What the suite runs on: a task (at a strength) and its motions.
struct Subject {
  std::unique_ptr<const TaskEvaluator> evaluator;
  std::vector<MotionUnderTest> motions;
  fs::path run_dir;  // a run's directory (robustness.json goes there), else empty
};

// "M3" -> 3; anything else -> 0.
int label_index(const std::string& label) {
  if (label.size() < 2 || label[0] != 'M') return 0;
  for (std::size_t k = 1; k < label.size(); ++k)
    if (!std::isdigit(static_cast<unsigned char>(label[k]))) return 0;
  return label.size() > 7 ? 0 : std::stoi(label.substr(1));
}

// The task of --task, refusing one whose name is not `expected` (the motion's or run's).
Task task_of_option(const std::string& option, const std::string& file, const std::string& field,
                    const std::string& expected) {
  Task task = load_task(resolve_task_path(option));
  if (!expected.empty() && task.name != expected)
    throw_field_error(file, field,
                      "expected a motion of task '" + task.name + "' (--task " + option + "), got '" + expected + "'");
  return task;
}

// Every motion of a finished run, as the run simulated them.
Subject open_run(const fs::path& dir, const std::string& task_option) {
  const RunView view = load_run_view(dir);
  if (!task_option.empty()) task_of_option(task_option, (dir / "run.json").string(), "task", view.task_name);
  RunProblem problem = open_run_problem(view, 1, "its robustness cannot be measured");
  Subject s;
  for (const RunMotion& m : view.motions)
    s.motions.push_back(MotionUnderTest{m.label, m.index, motion_parameters(problem.like, m.file)});
  s.evaluator = std::move(problem.evaluator);
  s.run_dir = dir;
  return s;
}

Subject open_motion_file(const fs::path& file, const nlohmann::json& motion, const std::string& task_option) {
  const std::string name = motion.value("task", std::string());
  const std::string label = motion.value("label", std::string("M0"));
  const fs::path run = file.parent_path().parent_path();
  if (task_option.empty() && file.parent_path().filename() == "motions" && fs::exists(run / "run.json")) {
    // A motion of a run: the run's task file, strength and shape.
    const RunView view = load_run_view(run);
    RunProblem problem = open_run_problem(view, 1, "its robustness cannot be measured");
    Subject s;
    s.motions.push_back(MotionUnderTest{label.empty() ? "M0" : label, label_index(label),
                                        motion_parameters(problem.like, file)});
    s.evaluator = std::move(problem.evaluator);
    return s;
  }
  Task task;
  if (!task_option.empty()) {
    task = task_of_option(task_option, file.string(), "task", name);
  } else {
    if (name.empty()) throw_field_error(file.string(), "task", "expected the name of the motion's task");
    try {
      task = load_task(resolve_task_path(name));
    } catch (const UserError&) {
      throw_field_error(file.string(), "task", "expected a task found as tasks/" + name + ".toml; give it with --task FILE");
    }
  }
  const nlohmann::json strength = motion.value("strength", nlohmann::json(1.0));
  if (!strength.is_number() || !(strength.get<double>() >= kMinStrength && strength.get<double>() <= kMaxStrength))
    throw_field_error(file.string(), "strength", "expected a number in [0.1, 10]");
  task.strength = strength.get<double>();
  Subject s;
  s.evaluator = std::make_unique<const TaskEvaluator>(std::move(task));
  s.motions.push_back(MotionUnderTest{label.empty() ? "M0" : label, label_index(label),
                                      s.evaluator->load_shaped_parameters(file.string())});
  return s;
}

Subject open_subject(const RobustnessArgs& a) {
  if (a.target.empty()) {
    if (a.task.empty()) throw UserError("robustness: expected a motion file, a run directory or --task FILE");
    Task task = load_task(resolve_task_path(a.task));
    const std::string m0 = task.m0;
    Subject s;
    s.evaluator = std::make_unique<const TaskEvaluator>(std::move(task));
    s.motions.push_back(MotionUnderTest{"M0", 0, s.evaluator->load_shaped_parameters(m0)});
    return s;
  }
  const fs::path target(a.target);
  if (fs::is_directory(target)) {
    if (!fs::exists(target / "run.json"))
      throw_field_error(a.target, "run.json", "expected a run directory (with run.json) or a motion file");
    return open_run(target, a.task);
  }
  const nlohmann::json j = read_json(target);  // "FILE: not valid JSON" or "cannot read"
  if (j.is_object() && j.contains("format")) {
    if (j["format"] != "diverse.motion")
      throw_field_error(a.target, "format", "expected \"diverse.motion\" (a motion file) or a parameter file with --task");
    return open_motion_file(target, j, a.task);
  }
  if (a.task.empty())
    throw_field_error(a.target, "format",
                      "expected a motion file (\"diverse.motion\") or a run directory; a parameter file needs --task FILE");
  Task task = load_task(resolve_task_path(a.task));
  Subject s;
  s.evaluator = std::make_unique<const TaskEvaluator>(std::move(task));
  s.motions.push_back(MotionUnderTest{"M0", 0, s.evaluator->load_shaped_parameters(a.target)});
  return s;
}

void run(const RobustnessArgs& a) {
  Subject subject = open_subject(a);
  RobustnessSuite suite;
  suite.seed = a.seed;
  suite.sigma = a.sigma;
  suite.parameter_samples = a.samples;
  suite.push_samples = a.samples;
  suite.push_speed = a.push;
  // The output paths are checked before the rollouts, so a bad one costs no time.
  if (!a.out.empty()) ensure_writable_directory(fs::absolute(fs::path(a.out)).parent_path());
  const int threads = a.threads > 0 ? a.threads : ThreadPool::hardware_threads();
  ThreadPool pool(threads);
  const TaskEvaluator& ev = *subject.evaluator;
  const std::vector<MotionRobustness> results = run_robustness_suite(ev, subject.motions, suite, pool);
  const nlohmann::json json = robustness_json(ev, suite, results);

  std::printf("robustness of %s (seed %llu: %d parameter samples at sigma %g, %d pushes of %g m/s, friction",
              ev.task().name.c_str(), static_cast<unsigned long long>(suite.seed), suite.parameter_samples,
              suite.sigma, suite.push_samples, suite.push_speed);
  for (double f : suite.friction_factors) std::printf(" x%g", f);
  std::printf(", half timestep)\n");
  for (std::size_t m = 0; m < results.size(); ++m) {
    std::printf("  %-4s C %-9.3g %s\n", results[m].label.c_str(), results[m].constraint,
                robustness_shares(json["motions"][m], "robustness").c_str());
  }
  if (!subject.run_dir.empty()) {
    write_json_atomic(subject.run_dir / "robustness.json", json);
    std::printf("wrote %s\n", (subject.run_dir / "robustness.json").string().c_str());
  }
  if (!a.out.empty()) {
    write_json_atomic(a.out, json);
    std::printf("wrote %s\n", a.out.c_str());
  }
}

void install(CLI::App& app) {
  auto args = std::make_shared<RobustnessArgs>();
  CLI::App* cmd = app.add_subcommand(
      "robustness", "The share of perturbed rollouts of a motion (or of a run's motions) that still meet the task");
  cmd->footer("Examples:\n"
              "  diverse robustness runs/jump_high    # every motion of a finished run\n"
              "  diverse robustness --task backflip   # a task's input motion");
  cmd->add_option("motion", args->target,
                  "A motion file, a run directory, or a parameter file of --task (default: --task's M0)");
  cmd->add_option("--task", args->task, "Task name or file (for a parameter file, or the task's M0)");
  cmd->add_option("--out", args->out, "Also write the results as JSON to FILE");
  cmd->add_option("--sigma", args->sigma, "Parameter perturbation (normalized units)")
      ->capture_default_str()
      ->check(number_in(0, kMaxRobustnessSigma, Bound::kOpen));
  cmd->add_option("--samples", args->samples, "Rollouts per kind for parameters and for pushes")
      ->capture_default_str()
      ->check(integer_in(1, kMaxRobustnessSamples));
  cmd->add_option("--push", args->push, "Push: change of the root's speed (m/s)")
      ->capture_default_str()
      ->check(number_in(0, kMaxPushSpeed));
  cmd->add_option("--seed", args->seed, "Suite seed")->capture_default_str()->check(unsigned_integer());
  cmd->add_option("--threads", args->threads, "Worker threads (0 = one per core)")
      ->capture_default_str()
      ->check(integer_in(0, kMaxThreads));
  cmd->callback([args] { run(*args); });
}

const bool registered = register_command(52, install);

}  // namespace
}  // namespace diverse::cli
