// `diverse bench [TASK]`: simulation throughput of a task, as ratios measured in one run.
//
//   diverse bench backflip --seconds 3
//
// Prints a table and, with --json, one JSON object. See src/eval/throughput.h.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>

#include "command.h"
#include "options.h"
#include "core/error.h"
#include "eval/throughput.h"
#include "task/task.h"

namespace diverse::cli {
namespace {

void install_bench(CLI::App& app) {
  struct Args {
    std::string task = "jump_high";
    double seconds = 2.0;
    int threads = 0;
    bool json = false;
    std::string character;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("bench", "Measure rollout throughput against raw mj_step");
  cmd->add_option("task", args->task, "Task name or path")->capture_default_str();
  cmd->add_option("--seconds", args->seconds, "Seconds per measurement")
      ->capture_default_str()
      ->check(number_in(0, 3600, Bound::kOpen));
  cmd->add_option("--threads", args->threads, "Threads for the parallel figure (0 = one per core)")
      ->capture_default_str()
      ->check(integer_in(0, kMaxThreads));
  cmd->add_flag("--json", args->json, "Print one JSON object");
  cmd->add_option("--character", args->character,
                  "A character with a free root (character file): measure it standing under stance control instead of a task");
  cmd->callback([args] {
    if (!(args->seconds > 0)) throw UserError("--seconds: expected a number > 0");
    if (args->threads < 0) throw UserError("--threads: expected an integer >= 0");
    if (!args->character.empty()) {
      const ThroughputReport r = measure_stance_throughput(args->character, {args->seconds, 1, 0});
      if (args->json) {
        nlohmann::json j = r.to_json();
        j["character"] = args->character;
        std::printf("%s\n", j.dump(2).c_str());
        return;
      }
      std::printf("character %s standing, %d steps per rollout\n", args->character.c_str(), r.rollout_steps);
      std::printf("  raw mj_step (the rollout's inputs replayed) %12.0f steps/s\n", r.raw_steps_per_second);
      std::printf("  rollout (stance control + joint drive)      %12.0f steps/s   %.1f %% of raw\n",
                  r.rollout_steps_per_second, 100.0 * r.rollout_ratio);
      std::printf("  rollouts, 1 thread                          %12.1f /s\n", r.rollouts_per_second_1);
      return;
    }
    Task task = load_task(resolve_task_path(args->task));
    if (!std::filesystem::exists(task.m0))
      throw UserError(task.file + ": m0: " + task.m0 + " does not exist");
    const TaskEvaluator evaluator(std::move(task));
    const ParameterSet m0 = evaluator.load_parameters(evaluator.task().m0);
    const ThroughputReport r =
        measure_throughput(evaluator, m0, {args->seconds, args->threads, 64});
    if (args->json) {
      nlohmann::json j = r.to_json();
      j["task"] = evaluator.task().name;
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    std::printf("task %s, %d steps per rollout of M0\n", evaluator.task().name.c_str(),
                r.rollout_steps);
    std::printf("  raw mj_step (M0's inputs replayed) %12.0f steps/s\n", r.raw_steps_per_second);
    std::printf("  rollout (control + recording)      %12.0f steps/s   %.1f %% of raw\n",
                r.rollout_steps_per_second, 100.0 * r.rollout_ratio);
    std::printf("  rollouts, 1 thread                 %12.1f /s\n", r.rollouts_per_second_1);
    std::printf("  rollouts, %d threads               %12.1f /s   speed-up %.2fx\n", r.threads,
                r.rollouts_per_second_n, r.speedup);
  });
}

const bool registered = register_command(40, install_bench);

}  // namespace
}  // namespace diverse::cli
