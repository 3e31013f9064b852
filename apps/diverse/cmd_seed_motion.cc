// `diverse seed-motion TASK`: finds the task's input motion M0 by CMA-ES on the
// constraint penalty, starting from the hand-authored jump the task names
// ([seed] base), with continuation on the scene object's height where the task asks for
// it (src/task/seed_motion.h), and writes the parameters to the task's m0 file.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <fstream>
#include <iomanip>
#include <string>

#include "command.h"
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
};

void run(const SeedArgs& args) {
  const Task task = load_task(resolve_task_path(args.task));
  const TaskEvaluator ev(task);
  const std::string start_path = args.start.empty() ? task.seed.base : args.start;
  if (start_path.empty()) {
    throw UserError(task.file + ": seed.base: expected the starting parameters (missing)");
  }
  const ParameterSet start = ev.load_parameters(start_path);
  SeedOptions options;
  options.threads = args.threads;
  options.generations = args.generations;
  options.log = [](const std::string& line) { std::printf("%s\n", line.c_str()); std::fflush(stdout); };
  const SeedResult r = seed_motion(task, start, options);
  // The task's m0 file only ever holds a motion that meets the task; a search that falls
  // short writes its best attempt beside it, to continue from with --start.
  const bool met = r.constraint == 0;
  std::string out = args.out;
  if (out.empty()) {
    out = task.m0;
    if (!met) {
      const std::string suffix = ".m0.json";
      out = out.size() > suffix.size() && out.compare(out.size() - suffix.size(), suffix.size(), suffix) == 0
                ? out.substr(0, out.size() - suffix.size()) + ".partial.json"
                : out + ".partial";
    }
  }
  nlohmann::json j;
  j["task"] = task.name;
  j["constraint"] = r.constraint;
  j["margin"] = r.margin;
  j["found_by"] = "diverse seed-motion " + task.name + " (from " + start_path + ", " +
                  std::to_string(r.evaluations) + " rollouts)";
  j["parameters"] = r.parameters.to_json();
  write_json_atomic(out, j);
  std::printf("C=%.6g margin=%.3f fell=%d evaluations=%lld seconds=%.1f -> %s\n", r.constraint,
              r.margin, r.fell ? 1 : 0, r.evaluations, r.seconds, out.c_str());
  if (!met)
    throw UserError(task.file + ": no motion meeting the task was found (best C = " +
                    std::to_string(r.constraint) + "); continue with `diverse seed-motion " +
                    task.name + " --start " + out + "`");
}

void install(CLI::App& app) {
  auto args = std::make_shared<SeedArgs>();
  CLI::App* cmd = app.add_subcommand(
      "seed-motion", "Find a task's input motion M0 by CMA-ES on its constraint penalty");
  cmd->add_option("task", args->task, "Task name (tasks/<name>.toml) or task file")->required();
  cmd->add_option("--start", args->start, "Starting parameters (default: the task's seed.base)");
  cmd->add_option("--out", args->out, "Output file (default: the task's m0 file)");
  cmd->add_option("--threads", args->threads, "Worker threads")->check(CLI::Range(1, 256));
  cmd->add_option("--generations", args->generations,
                  "CMA-ES generations per stage (default: the task's seed.generations)")
      ->check(CLI::Range(1, 100000));
  cmd->callback([args] { run(*args); });
}

const bool registered = register_command(40, install);

}  // namespace
}  // namespace diverse::cli
