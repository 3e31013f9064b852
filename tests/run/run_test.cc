// End-to-end tests of `diverse run` and `diverse resume` on a short run of a real task:
// thread-count independence, exact resume after kill -9, and the errors users meet.
#include <gtest/gtest.h>

#include "support/cli.h"
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>

#include "io/files.h"
#include "io/motion_record.h"
#include "run/run.h"
#include "support/scratch.h"
#include "support/task_variant.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

using Result = cli_test::CliResult;
using cli_test::run_cli;

fs::path scratch(const std::string& name) {
  const fs::path dir = test_files::scratch_dir("run_test_" + name);
  return dir;
}

const std::string kTask = std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml";
// Short but real: 2 variations, 8 samples per generation, 5 generations.
// A small initial step: under the half-timestep check the high jump's feasible
// neighbourhood is thin, and from 0.03 a variation can still stand at M0 after 5
// generations.
const std::string kShort =
    kTask + " --n 2 --popsize 8 --sigma0 0.01 --generations 5 --seed 3 --quiet --no-render";

TEST(Run, SameSeedGivesIdenticalSummaryWithOneAndTwoThreads) {
  const fs::path one = scratch("threads1"), two = scratch("threads2");
  Result a = run_cli("run " + kShort + " --threads 1 --out " + one.string());
  ASSERT_EQ(a.status, 0) << a.output;
  Result b = run_cli("run " + kShort + " --threads 2 --out " + two.string());
  ASSERT_EQ(b.status, 0) << b.output;
  const auto sa = read_json(one / "summary.json");
  const auto sb = read_json(two / "summary.json");
  EXPECT_EQ(sa["timing"]["threads"], 1);
  EXPECT_EQ(sb["timing"]["threads"], 2);
  EXPECT_EQ(without_timing(sa), without_timing(sb));
  EXPECT_EQ(read_file(one / "log.jsonl"), read_file(two / "log.jsonl"));

  // The run directory holds what SPEC section 7 lists.
  EXPECT_EQ(sa["N"], 2);
  EXPECT_EQ(sa["motions"].size(), 3u);
  for (const char* metric : {"hf", "md", "wja"}) EXPECT_EQ(sa["distances"][metric].size(), 3u);
  for (int i = 0; i <= 2; ++i) {
    const fs::path motion = one / "motions" / ("m" + std::to_string(i) + ".json");
    ASSERT_TRUE(fs::exists(motion));
    ASSERT_TRUE(fs::exists(one / "model" / ("m" + std::to_string(i) + ".xml")));
    // Every exported motion replays exactly in plain MuJoCo.
    int steps = 0;
    EXPECT_LT(replay_motion_file(motion, &steps), 1e-6) << motion;
    EXPECT_GT(steps, 100);
  }
  EXPECT_TRUE(fs::exists(one / "paths" / "m1.json"));
  EXPECT_TRUE(fs::exists(one / "checkpoint.json"));
  // M0 is the committed input motion: it satisfies its task. Under the default rules
  // (constraints dominant, variations standing at their best samples) every variation
  // does too, and each has moved away from M0.
  EXPECT_TRUE(sa["all_satisfied"].get<bool>());
  for (int i = 0; i <= 2; ++i) EXPECT_EQ(sa["motions"][i]["constraint"], 0.0) << i;
  for (int i = 1; i <= 2; ++i) EXPECT_GT(sa["distances"]["md"][0][i].get<double>(), 0.0) << i;

  // Every returned motion holds at half the timestep, though the optimizer checked only
  // the samples a variation moved to: fewer checks than samples that met the task at the
  // task's timestep.
  for (int i = 0; i <= 2; ++i) EXPECT_TRUE(sa["motions"][i]["half_timestep"]["holds"].get<bool>()) << i;
  const auto& steps = sa["steps"];
  const long long met = steps["rollouts"]["met"]["rollouts"].get<long long>();
  long long checks = 0, check_steps = 0, rollout_steps = 0;
  for (const auto& [result, entry] : steps["half_timestep"].items()) {
    checks += entry["rollouts"].get<long long>();
    check_steps += entry["steps"].get<long long>();
  }
  long long rollouts = 0;
  for (const auto& [result, entry] : steps["rollouts"].items()) {
    rollouts += entry["rollouts"].get<long long>();
    rollout_steps += entry["steps"].get<long long>();
  }
  EXPECT_EQ(rollouts, sa["evaluations"].get<long long>());
  EXPECT_EQ(checks, sa["confirmations"].get<long long>());
  EXPECT_GT(checks, 0);
  EXPECT_LT(checks, met);
  EXPECT_EQ(steps["total"].get<long long>(), rollout_steps + check_steps);
  EXPECT_GE(steps["after_decided"].get<long long>(), 0);
  EXPECT_LT(steps["after_decided"].get<long long>(), rollout_steps);
  // The robustness suite's shares of every motion, by kind (robust/robustness.h), with
  // its every rollout in robustness.json.
  ASSERT_EQ(sa["robustness"]["motions"].size(), 3u);
  for (const auto& m : sa["robustness"]["motions"]) {
    EXPECT_EQ(m["count"], 19);
    EXPECT_LE(m["held"].get<int>(), 19);
    EXPECT_EQ(m["kinds"]["parameters"]["count"], 8);
    EXPECT_EQ(m["kinds"]["half_timestep"]["count"], 1);
  }
  EXPECT_EQ(read_json(one / "robustness.json")["motions"].size(), 3u);

  // Every motion's foot slip (task/foot_slip.h), as `diverse foot-slip` measures it from
  // the motion files, and in the report's table.
  const Result slip = run_cli("foot-slip --json " + one.string());
  ASSERT_EQ(slip.status, 0) << slip.output;
  const nlohmann::json measured = nlohmann::json::parse(slip.output);
  ASSERT_EQ(measured.size(), 3u);
  for (int i = 0; i <= 2; ++i) {
    const auto& f = sa["motions"][i]["foot_slip"];
    EXPECT_EQ(f, measured[i]["foot_slip"]) << i;
    EXPECT_EQ(measured[i]["label"], "M" + std::to_string(i));
    EXPECT_EQ(f["left"]["stances"], 2) << i;  // standing, then landed
    EXPECT_GE(f["largest_per_stance"].get<double>(), f["left"]["mean_per_stance"].get<double>()) << i;
  }
  const Result report = run_cli("report " + one.string());
  ASSERT_EQ(report.status, 0) << report.output;
  EXPECT_NE(report.output.find("| left stances | left cm per stance |"), std::string::npos) << report.output;
  EXPECT_NE(report.output.find("| M2 | 2 | "), std::string::npos) << report.output;
}

// summary.json's timing.rollouts: every rollout of the run (M0 once, then N x lambda per
// generation) with its CPU time, and the batches the strategy asked for: one per
// generation (round-robin at best samples, simultaneous), or one per variation and
// generation (round-robin at means, each batch but a generation's first with the
// previous variation's new mean, and that last mean alone at the generation's end).
// Without --generations a run takes the task's budget ([diversity] generations); the
// option overrides it.
TEST(Run, TheTasksGenerationBudgetUnlessTheOptionSaysOtherwise) {
  const fs::path task =
      test_files::task_variant("jump_forward", "three_generations", {}, {{"diversity", "generations = 3"}});
  const std::string common =
      task.string() + " --n 2 --popsize 8 --sigma0 0.01 --seed 3 --quiet --no-render --threads 2";
  const fs::path own = scratch("budget_task"), given = scratch("budget_option");
  Result a = run_cli("run " + common + " --out " + own.string());
  ASSERT_EQ(a.status, 0) << a.output;
  Result b = run_cli("run " + common + " --generations 2 --out " + given.string());
  ASSERT_EQ(b.status, 0) << b.output;
  const auto sa = read_json(own / "summary.json");
  const auto sb = read_json(given / "summary.json");
  EXPECT_EQ(sa["evaluations"], 1 + 3 * 2 * 8);
  EXPECT_EQ(sb["evaluations"], 1 + 2 * 2 * 8);
}

TEST(Run, TimingHoldsTheRolloutsAndTheStrategysBatches) {
  struct Case {
    const char* options;
    long long evaluations, batches, largest;
  };
  for (const Case& c : {Case{"--strategy round-robin", 1 + 5 * 2 * 8, 1 + 5, 2 * 8},
                        Case{"--strategy simultaneous", 1 + 5 * 2 * 8, 1 + 5, 2 * 8},
                        Case{"--strategy round-robin --point mean", 1 + 5 * 2 * (8 + 1), 1 + 5 * 3, 8 + 1}}) {
    SCOPED_TRACE(c.options);
    const fs::path dir = scratch(std::string("timing_") + std::to_string(c.batches) + "_" + std::to_string(c.largest));
    Result r = run_cli("run " + kShort + " --threads 2 " + c.options + " --out " + dir.string());
    ASSERT_EQ(r.status, 0) << r.output;
    const auto s = read_json(dir / "summary.json");
    EXPECT_EQ(s["evaluations"], c.evaluations);
    const auto& rollouts = s["timing"]["rollouts"];
    EXPECT_EQ(rollouts["count"], c.evaluations);
    EXPECT_EQ(rollouts["batches"], c.batches);
    EXPECT_EQ(rollouts["batch_size"]["max"], c.largest);
    EXPECT_EQ(rollouts["batch_size"]["min"], 1);  // M0
    const auto deciles = rollouts["cpu_ms"]["deciles"].get<std::vector<double>>();
    ASSERT_EQ(deciles.size(), 11u);
    EXPECT_GT(deciles.front(), 0.0);
    EXPECT_TRUE(std::is_sorted(deciles.begin(), deciles.end()));
    EXPECT_TRUE(s["all_satisfied"].get<bool>());
  }
}

TEST(Run, ResumeAfterKillGivesTheSameSummary) {
  const fs::path whole = scratch("whole"), killed = scratch("killed");
  const std::string args = kShort + " --generations 6 --threads 1 --checkpoint-seconds 0";
  Result a = run_cli("run " + args + " --out " + whole.string());
  ASSERT_EQ(a.status, 0) << a.output;

  // Start the same run and kill -9 it once a checkpoint past generation 2 exists.
  ASSERT_GE(cli_test::run_then_kill(args, killed, 2), 2);
  ASSERT_FALSE(fs::exists(killed / "summary.json")) << "the run finished before it was killed";

  Result r = run_cli("resume " + killed.string() + " --threads 2 --quiet --no-render");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(without_timing(read_json(whole / "summary.json")),
            without_timing(read_json(killed / "summary.json")));
  EXPECT_EQ(read_file(whole / "log.jsonl"), read_file(killed / "log.jsonl"));
}

TEST(RunErrors, OneLineMessagesAndNonZeroExit) {
  const fs::path out = scratch("errors");
  struct Case {
    std::string args, message;
  };
  const Case cases[] = {
      {"run no_such_task --out " + out.string(), "no_such_task"},
      {"run " + kTask + " --n -1 --out " + out.string(), "--n: expected an integer in [1, 100], got '-1'"},
      {"run " + kTask + " --k -2 --out " + out.string(), "--k: expected a number in [0, 1000000000], got '-2'"},
      {"run " + kTask + " --generations 0 --out " + out.string(), "--generations: expected an integer in [1, 1000000], got '0'"},
      {"run " + kTask + " --strategy sideways --out " + out.string(), "sideways"},
      {"run " + kTask + " --constraints soft --out " + out.string(),
       "--constraints: expected one of dominant, penalty, got 'soft'"},
      {"run " + kTask + " --point median --out " + out.string(),
       "--point: expected one of best-sample, mean, got 'median'"},
      {"run " + kTask + " --sigma0 1.5 --out " + out.string(), "--sigma0: expected a number in (0, 1]"},
      {"run " + kTask + " --metric euclid --out " + out.string(), "--metric: unknown metric 'euclid'"},
      {"resume " + out.string() + "/nowhere", "not a directory"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const Result r = run_cli(c.args);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "expected one line: " << r.output;
    EXPECT_EQ(r.output.rfind("diverse: error: ", 0), 0u) << r.output;
  }
}

TEST(RunErrors, ResumeRefusesADirectoryThatIsNotARun) {
  const fs::path dir = scratch("notarun");
  fs::create_directories(dir);
  const Result r = run_cli("resume " + dir.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("not a run directory"), std::string::npos) << r.output;
}

TEST(RunErrors, CorruptCheckpointAndExistingRun) {
  const fs::path dir = scratch("corrupt");
  Result a = run_cli("run " + kShort + " --generations 1 --threads 2 --out " + dir.string());
  ASSERT_EQ(a.status, 0) << a.output;
  const std::string summary = read_file(dir / "summary.json");

  // An existing run is never overwritten without --force.
  Result again = run_cli("run " + kShort + " --generations 1 --out " + dir.string());
  EXPECT_NE(again.status, 0);
  EXPECT_NE(again.output.find("already holds a run (use --force"), std::string::npos) << again.output;
  EXPECT_EQ(read_file(dir / "summary.json"), summary);

  // A truncated checkpoint is reported, not trusted.
  const std::string checkpoint = read_file(dir / "checkpoint.json");
  write_file_atomic(dir / "checkpoint.json", checkpoint.substr(0, checkpoint.size() / 2));
  Result r = run_cli("resume " + dir.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("checkpoint.json: not valid JSON"), std::string::npos) << r.output;

  // A checkpoint of another shape is reported too.
  write_file_atomic(dir / "checkpoint.json", "{\"format\": \"something else\"}");
  r = run_cli("resume " + dir.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("checkpoint.json: format"), std::string::npos) << r.output;

  // --force replaces the run.
  Result forced = run_cli("run " + kShort + " --generations 1 --force --out " + dir.string());
  EXPECT_EQ(forced.status, 0) << forced.output;
}

}  // namespace
}  // namespace diverse
