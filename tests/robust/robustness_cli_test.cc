// `diverse robustness` end to end, through the built tool: on a motion file (the table
// line, the JSON with the suite's definition, the same file on 1 and 2 threads), on a
// task's input motion, on a run directory (RUN/robustness.json, one entry per motion
// M0..MN), and `diverse report RUN` showing the shares of each motion.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "io/files.h"
#include "support/cli.h"
#include "support/scratch.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

const std::string kSource = DIVERSE_SOURCE_DIR;

TEST(RobustnessCli, MotionFileTaskInputAndRun) {
  const fs::path dir = test_files::scratch_dir("robustness_cli");
  fs::create_directories(dir);
  const cli_test::CliResult sim = cli_test::run_cli("simulate jump_high --no-film --out " + (dir / "sim").string());
  ASSERT_EQ(sim.status, 0) << sim.output;

  // A motion file, on one and on two threads: the same JSON.
  const std::string motion = (dir / "sim/motion.json").string();
  const std::string suite = " --samples 2 --sigma 0.01 --push 0.2 --seed 7 ";
  const cli_test::CliResult one =
      cli_test::run_cli("robustness " + motion + suite + "--threads 1 --out " + (dir / "one.json").string());
  ASSERT_EQ(one.status, 0) << one.output;
  EXPECT_NE(one.output.find("robustness of jump_high"), std::string::npos) << one.output;
  EXPECT_NE(one.output.find("M0"), std::string::npos) << one.output;
  EXPECT_NE(one.output.find("params "), std::string::npos) << one.output;
  EXPECT_NE(one.output.find(", all "), std::string::npos) << one.output;
  const cli_test::CliResult two =
      cli_test::run_cli("robustness " + motion + suite + "--threads 2 --out " + (dir / "two.json").string());
  ASSERT_EQ(two.status, 0) << two.output;
  EXPECT_EQ(read_file(dir / "one.json"), read_file(dir / "two.json"));
  const nlohmann::json j = read_json(dir / "one.json");
  EXPECT_EQ(j["format"], "diverse.robustness");
  EXPECT_EQ(j["task"], "jump_high");
  EXPECT_EQ(j["suite"]["seed"], 7);
  EXPECT_EQ(j["suite"]["sigma"], 0.01);
  EXPECT_EQ(j["suite"]["push_speed"], 0.2);
  EXPECT_EQ(j["suite"]["parameter_samples"], 2);
  EXPECT_EQ(j["suite"]["push_directions"].size(), 2u);  // planar: forward and backward
  ASSERT_EQ(j["motions"].size(), 1u);
  const nlohmann::json& m = j["motions"][0];
  EXPECT_EQ(m["constraint"], 0.0);
  EXPECT_EQ(m["kinds"]["parameters"]["count"], 2);
  EXPECT_EQ(m["kinds"]["pushes"]["count"], 2);
  EXPECT_EQ(m["kinds"]["friction"]["count"], 2);
  EXPECT_EQ(m["kinds"]["half_timestep"]["count"], 1);
  EXPECT_EQ(m["count"], 7);
  for (const auto& r : m["kinds"]["pushes"]["rollouts"]) EXPECT_GE(r["time"].get<double>(), 0.0);

  // The task's input motion (the same parameters as the simulated M0): the same results.
  const cli_test::CliResult task =
      cli_test::run_cli("robustness --task jump_high" + suite + "--threads 2 --out " + (dir / "task.json").string());
  ASSERT_EQ(task.status, 0) << task.output;
  EXPECT_EQ(read_json(dir / "task.json")["motions"], j["motions"]);

  // A run: every motion, robustness.json in the run, and its shares in the report.
  const fs::path run = dir / "run";
  const cli_test::CliResult made = cli_test::run_cli(
      "run jump_high --n 1 --popsize 2 --generations 1 --threads 2 --quiet --no-render --out " + run.string());
  ASSERT_EQ(made.status, 0) << made.output;
  // The run ran the suite on its motions itself: its report shows the shares.
  ASSERT_TRUE(fs::exists(run / "robustness.json"));
  const cli_test::CliResult run_report = cli_test::run_cli("report " + run.string());
  ASSERT_EQ(run_report.status, 0) << run_report.output;
  EXPECT_NE(run_report.output.find("robustness"), std::string::npos) << run_report.output;
  const cli_test::CliResult r = cli_test::run_cli("robustness " + run.string() + " --samples 1 --threads 2");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json rj = read_json(run / "robustness.json");
  ASSERT_EQ(rj["motions"].size(), 2u);
  EXPECT_EQ(rj["motions"][0]["label"], "M0");
  EXPECT_EQ(rj["motions"][1]["label"], "M1");
  EXPECT_EQ(rj["motions"][1]["index"], 1);
  EXPECT_NE(r.output.find("wrote " + (run / "robustness.json").string()), std::string::npos) << r.output;
  // One motion of the run alone: the same entry as in the run's file (seeds follow M_i).
  const cli_test::CliResult m1 = cli_test::run_cli("robustness " + (run / "motions/m1.json").string() +
                                                   " --samples 1 --threads 1 --out " + (dir / "m1.json").string());
  ASSERT_EQ(m1.status, 0) << m1.output;
  EXPECT_EQ(read_json(dir / "m1.json")["motions"][0], rj["motions"][1]);
  const cli_test::CliResult report = cli_test::run_cli("report " + run.string());
  ASSERT_EQ(report.status, 0) << report.output;
  EXPECT_NE(report.output.find("| run | motion | robustness"), std::string::npos) << report.output;
  EXPECT_NE(report.output.find("| M0 | params "), std::string::npos) << report.output;
  EXPECT_NE(report.output.find("| M1 | params "), std::string::npos) << report.output;
  // A broken robustness.json is one line naming it.
  write_file_atomic(run / "robustness.json", R"({"format": "diverse.robustness", "motions": [{"label": "M0"}]})");
  const cli_test::CliResult broken = cli_test::run_cli("report " + run.string());
  EXPECT_EQ(broken.status, 2) << broken.output;
  EXPECT_NE(broken.output.find("robustness.json: motions[].kinds: expected"), std::string::npos) << broken.output;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace diverse
