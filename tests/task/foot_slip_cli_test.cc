// `diverse replay` and `diverse foot-slip` measure how far a motion's planted feet slide
// (task/foot_slip.h): on the bird robot's committed input walk, 15 stances a side and
// 4-6 cm of sliding per stance (the figure the measure was made to catch); a motion
// whose task file cannot be found is still replayed, and bad paths are one-line errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "io/files.h"
#include "support/cli.h"
#include "support/scratch.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

TEST(FootSlipCli, TheBirdRobotsInputWalkSlidesCentimetresPerStance) {
  const fs::path dir = test_files::scratch_dir("foot_slip_cli_walk");
  const auto sim = cli_test::run_cli("simulate " + kTasks + "robot_silly_walk.toml --out " + dir.string() + " --no-film");
  ASSERT_EQ(sim.status, 0) << sim.output;
  const std::string motion = (dir / "motion.json").string();

  const auto replay = cli_test::run_cli("replay " + motion);
  ASSERT_EQ(replay.status, 0) << replay.output;
  EXPECT_NE(replay.output.find("foot slip, left  feet: 15 stances"), std::string::npos) << replay.output;
  EXPECT_NE(replay.output.find("foot slip, right feet: 15 stances"), std::string::npos) << replay.output;

  const auto json = cli_test::run_cli("foot-slip --json " + motion);
  ASSERT_EQ(json.status, 0) << json.output;
  const nlohmann::json measured = nlohmann::json::parse(json.output);
  ASSERT_EQ(measured.size(), 1u);
  EXPECT_EQ(measured[0]["file"], motion);
  for (const char* side : {"left", "right"}) {
    const nlohmann::json& s = measured[0]["foot_slip"][side];
    EXPECT_EQ(s["stances"], 15) << side;
    EXPECT_EQ(s["stance_slides"].size(), 15u) << side;
    // Measured at the time of writing: 0.675 and 0.669 m in all, 4.5 cm per stance, 6.1
    // and 6.5 cm at most, up to 1.75 and 2.8 m/s.
    EXPECT_NEAR(s["total"].get<double>(), 0.67, 0.05) << side;
    EXPECT_NEAR(s["mean_per_stance"].get<double>(), 0.045, 0.005) << side;
    EXPECT_GT(s["largest_per_stance"].get<double>(), s["mean_per_stance"].get<double>()) << side;
    EXPECT_GT(s["max_speed"].get<double>(), 1.0) << side;
  }

  const auto table = cli_test::run_cli("foot-slip " + motion);
  ASSERT_EQ(table.status, 0) << table.output;
  EXPECT_NE(table.output.find("| " + motion + " | M0 | left | 15 | 0.6"), std::string::npos) << table.output;
  fs::remove_all(dir);
}

TEST(FootSlipCli, AMotionWithoutATaskFileIsReplayedWithoutTheMeasure) {
  const fs::path dir = test_files::scratch_dir("foot_slip_cli_orphan");
  const auto sim = cli_test::run_cli("simulate " + kTasks + "jump_high.toml --out " + dir.string() + " --no-film");
  ASSERT_EQ(sim.status, 0) << sim.output;
  nlohmann::json motion = read_json(dir / "motion.json");
  motion["task"] = "no_such_task";
  write_json_atomic(dir / "motion.json", motion);
  const std::string path = (dir / "motion.json").string();

  const auto replay = cli_test::run_cli("replay " + path);
  EXPECT_EQ(replay.status, 0) << replay.output;
  EXPECT_NE(replay.output.find("foot slip: not measured (no task file for task 'no_such_task'; give it with --task FILE)"),
            std::string::npos)
      << replay.output;
  const auto given = cli_test::run_cli("replay " + path + " --task " + kTasks + "jump_high.toml");
  EXPECT_NE(given.output.find("foot slip, left  feet: 2 stances"), std::string::npos) << given.output;

  const auto slip = cli_test::run_cli("foot-slip " + path);
  EXPECT_EQ(slip.status, 2) << slip.output;
  EXPECT_NE(slip.output.find(path + ": task: the motion's task file 'no_such_task' was not found; give it with --task FILE"),
            std::string::npos)
      << slip.output;
  fs::remove_all(dir);
}

TEST(FootSlipCli, PathsThatAreNotMotionsAreOneLineErrors) {
  const fs::path dir = test_files::scratch_dir("foot_slip_cli_bad");
  fs::create_directories(dir);
  const auto missing = cli_test::run_cli("foot-slip " + (dir / "nothing.json").string());
  EXPECT_EQ(missing.status, 2);
  EXPECT_EQ(missing.output, "diverse: error: " + (dir / "nothing.json").string() + ": no such motion file or run directory\n");
  const auto empty = cli_test::run_cli("foot-slip " + dir.string());
  EXPECT_EQ(empty.status, 2);
  EXPECT_EQ(empty.output, "diverse: error: " + dir.string() + ": not a run directory (no motions/) and not a motion file\n");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace diverse
