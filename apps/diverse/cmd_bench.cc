// `diverse bench [TASK]`: simulation throughput of a task, as ratios measured in one run.
//
//   diverse bench backflip --rounds 7 --seconds 0.5
//
// Raw mj_step, the rollout and the batch on 1 and on N threads are measured interleaved
// in short rounds; the table has each figure's median over the rounds and its spread.
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

constexpr long long kMaxRounds = 1000;
constexpr long long kMaxBatch = 100000;

// "90.9 % median, 88.0 to 93.2 % over 7 rounds (middle half 89.5 to 92.0 %)"
void print_spread(const char* label, const Spread& s, double scale, const char* unit, int rounds) {
  std::printf("  %-38s %7.*f%s median, %.*f to %.*f%s over %d rounds (middle half %.*f to %.*f%s)\n", label,
              scale > 1 ? 1 : 2, scale * s.median, unit, scale > 1 ? 1 : 2, scale * s.min, scale > 1 ? 1 : 2,
              scale * s.max, unit, rounds, scale > 1 ? 1 : 2, scale * s.q1, scale > 1 ? 1 : 2, scale * s.q3, unit);
}

void print_load(const ThroughputReport& r) {
  if (r.load_before >= 0)
    std::printf("  load average %.1f before, %.1f after (other jobs on the machine)\n", r.load_before,
                r.load_after);
}

void install_bench(CLI::App& app) {
  struct Args {
    std::string task = "jump_high";
    double seconds = 0.5;
    int rounds = 7;
    int threads = 0;
    int batch = 64;
    bool json = false;
    std::string character;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("bench", "Measure rollout throughput against raw mj_step");
  cmd->footer("Examples:\n"
              "  diverse bench jump_high --threads 2 --rounds 7\n"
              "  diverse bench --character assets/characters/robot3d.toml");
  cmd->add_option("task", args->task, "Task name or path")->capture_default_str();
  cmd->add_option("--seconds", args->seconds, "Seconds per measurement in each round")
      ->capture_default_str()
      ->check(number_in(0, 3600, Bound::kOpen));
  cmd->add_option("--rounds", args->rounds, "Rounds of interleaved measurements (median and spread over them)")
      ->capture_default_str()
      ->check(integer_in(1, kMaxRounds));
  cmd->add_option("--threads", args->threads, "Threads for the parallel figure (0 = one per core)")
      ->capture_default_str()
      ->check(integer_in(0, kMaxThreads));
  cmd->add_option("--batch", args->batch, "Samples per batch of the parallel figure (a generation's)")
      ->capture_default_str()
      ->check(integer_in(1, kMaxBatch));
  cmd->add_flag("--json", args->json, "Print one JSON object");
  cmd->add_option("--character", args->character,
                  "A character with a free root (character file): measure it standing under stance control instead of a task");
  cmd->callback([args] {
    if (!(args->seconds > 0)) throw UserError("--seconds: expected a number > 0");
    if (args->threads < 0) throw UserError("--threads: expected an integer >= 0");
    const ThroughputOptions options{args->seconds, args->threads, args->batch, args->rounds};
    if (!args->character.empty()) {
      const ThroughputReport r = measure_stance_throughput(args->character, options);
      if (args->json) {
        nlohmann::json j = r.to_json();
        j["character"] = args->character;
        std::printf("%s\n", j.dump(2).c_str());
        return;
      }
      std::printf("character %s standing, %d steps per rollout; %d rounds of %g s per measurement\n",
                  args->character.c_str(), r.rollout_steps, r.rounds, r.seconds);
      std::printf("  raw mj_step (the rollout's inputs replayed) %10.0f steps per CPU second (median)\n",
                  r.raw_steps_per_second);
      std::printf("  rollout (stance control + joint drive)      %10.0f steps per CPU second (median)\n",
                  r.rollout_steps_per_second);
      print_spread("rollout / raw", r.ratio, 100.0, " %", r.rounds);
      std::printf("  rollouts, 1 thread                          %10.1f /s\n", r.rollouts_per_second_1);
      print_load(r);
      return;
    }
    Task task = load_task(resolve_task_path(args->task));
    if (!std::filesystem::exists(task.m0))
      throw UserError(task.file + ": m0: " + task.m0 + " does not exist");
    const TaskEvaluator evaluator(std::move(task));
    const ParameterSet m0 = evaluator.load_parameters(evaluator.task().m0);
    const ThroughputReport r = measure_throughput(evaluator, m0, options);
    if (args->json) {
      nlohmann::json j = r.to_json();
      j["task"] = evaluator.task().name;
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    std::printf("task %s, %d steps per rollout of M0; %d rounds of %g s per measurement\n",
                evaluator.task().name.c_str(), r.rollout_steps, r.rounds, r.seconds);
    std::printf("  raw mj_step (M0's inputs replayed)     %10.0f steps per CPU second (median)\n",
                r.raw_steps_per_second);
    std::printf("  rollout (control + recording)          %10.0f steps per CPU second (median)\n",
                r.rollout_steps_per_second);
    print_spread("rollout / raw", r.ratio, 100.0, " %", r.rounds);
    std::printf("  rollouts, 1 thread                     %10.1f /s (median)\n", r.rollouts_per_second_1);
    std::printf("  rollouts, %d threads                    %10.1f /s (median)\n", r.threads,
                r.rollouts_per_second_n);
    char label[64];
    std::snprintf(label, sizeof label, "speed-up 1 -> %d threads", r.threads);
    print_spread(label, r.speedup_spread, 1.0, "x", r.rounds);
    print_spread("  the same from CPU time (free cores)", r.speedup_cpu, 1.0, "x", r.rounds);
    print_spread("process's share of those cores", r.cpu_share, 100.0, " %", r.rounds);
    if (r.cpu_share.median < 0.95)
      std::printf("  (other jobs held the cores: the speed-up understates what %d threads do on a free machine)\n",
                  r.threads);
    print_load(r);
  });
}

const bool registered = register_command(40, install_bench);

}  // namespace
}  // namespace diverse::cli
