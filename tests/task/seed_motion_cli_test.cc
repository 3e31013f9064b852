// `diverse seed-motion` keeps the task's m0 file for motions that meet the task: a search
// that falls short writes its best attempt beside it and says how to continue. With
// --robustness-check it measures a motion and its neighbourhood instead of searching.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "io/files.h"
#include "support/cli.h"
#include "support/scratch.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

// A planar-human task NAME in DIR with jump_forward's constraints (land 1 m ahead), whose
// [seed] table starts from BASE (a file under the source tree) and adds SEED_EXTRA.
fs::path write_forward_task(const fs::path& dir, const std::string& name, const std::string& base,
                            const std::string& seed_extra = "") {
  const std::string source = DIVERSE_SOURCE_DIR;
  const fs::path file = dir / (name + ".toml");
  write_file_atomic(file,
                    "name = \"" + name + "\"\n"
                    "character = \"" + source + "/assets/characters/human2d.xml\"\n"
                    "metric = \"md\"\n"
                    "variations = 4\n"
                    "m0 = \"" + name + ".m0.json\"\n"
                    "[controller]\ntype = \"jump2d\"\n"
                    "[constraints]\nweight = 5000.0\nfall_penalty = 100000.0\nlanding = { center = 1.0, half_width = 0.15 }\n"
                    "[seed]\nbase = \"" + source + "/" + base + "\"\ngenerations = 1\n" + seed_extra);
  return file;
}

TEST(SeedMotionCli, AShortSearchThatFailsWritesAPartialFileNotTheM0) {
  const fs::path dir = test_files::scratch_dir("seed_motion_cli_test_partial");
  fs::create_directories(dir);
  // Starting from the hand-authored small in-place jump, which one generation of search
  // cannot turn into a 1 m forward jump.
  write_forward_task(dir, "short", "tasks/base_jump.json");
  // At strength 2: the hint to go on must say so again, or it would search another problem.
  const auto r = cli_test::run_cli("seed-motion " + (dir / "short.toml").string() + " --threads 2 --strength 2");
  EXPECT_NE(r.status, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir / "short.m0.json"));
  ASSERT_TRUE(fs::exists(dir / "short.partial.json")) << r.output;
  EXPECT_GT(read_json(dir / "short.partial.json")["constraint"].get<double>(), 0.0);
  EXPECT_NE(r.output.find("no motion meeting the task was found"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--start " + (dir / "short.partial.json").string() + " --strength 2`"), std::string::npos)
      << r.output;
}

// A continuation over landing distances keeps every stage's result, and a search can
// start at a later stage from it.
TEST(SeedMotionCli, EveryStageIsKeptAndASearchGoesOnFromALaterStage) {
  const fs::path dir = fs::temp_directory_path() / ("diverse_seed_motion_cli_test_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  // Stage 0 lands near where jump_high's input motion lands (0.13 m), which it meets at
  // once; stage 1 asks for 1 m, which one generation does not reach.
  write_forward_task(dir, "far", "tasks/jump_high.m0.json", "distances = [0.1, 1.0]\n");
  const std::string task = (dir / "far.toml").string();
  const auto first = cli_test::run_cli("seed-motion " + task + " --threads 2");
  EXPECT_NE(first.status, 0) << first.output;
  const fs::path stage0 = dir / "far.stage0.json";
  ASSERT_TRUE(fs::exists(stage0)) << first.output;
  EXPECT_NE(first.output.find("stage 0 ends with C=0 -> " + stage0.string()), std::string::npos) << first.output;
  const nlohmann::json j = read_json(stage0);
  EXPECT_EQ(j["stage"], 0);
  EXPECT_DOUBLE_EQ(j["stage_value"].get<double>(), 0.1);
  EXPECT_EQ(j["constraint"].get<double>(), 0.0);
  EXPECT_EQ(j["continue_with"], "diverse seed-motion " + task + " --start " + (dir / "far").string() +
                                    ".stage0.json --from-stage 1");
  EXPECT_FALSE(fs::exists(dir / "far.stage1.json")) << "the last stage is the task: its result is the m0 or partial file";

  // Going on from stage 1 skips stage 0.
  const auto second = cli_test::run_cli("seed-motion " + task + " --start " + stage0.string() + " --from-stage 1");
  EXPECT_EQ(second.output.find("stage 0"), std::string::npos) << second.output;
  EXPECT_NE(second.output.find("stage 1 (landing at 1.000 m)"), std::string::npos) << second.output;
  EXPECT_NE(read_json(dir / "far.partial.json")["found_by"].get<std::string>().find("--from-stage 1"),
            std::string::npos);

  const auto beyond = cli_test::run_cli("seed-motion " + task + " --from-stage 2");
  EXPECT_EQ(beyond.status, 2) << beyond.output;
  EXPECT_NE(beyond.output.find(task + ": --from-stage: expected a stage from 0 to 1 (got 2)"), std::string::npos)
      << beyond.output;
}

TEST(SeedMotionCli, RobustnessCheckReportsBothTimestepsAndTheNeighbourhood) {
  const auto r = cli_test::run_cli(
      "seed-motion jump_forward --robustness-check --check-sigmas 1e-6 0.5 --check-samples 3");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("C = 0 at the task's timestep, 0 with it halved"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("landing spots at the two timesteps differ by 0.0"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("sigma 1e-06: 3 of 3 perturbations meet the task (100 %)"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("sigma 0.5: 0 of 3 perturbations meet the task (0 %)"),
            std::string::npos)
      << r.output;
}

TEST(SeedMotionCli, RobustnessCheckOfAMissingFileSaysWhichFile) {
  const auto r = cli_test::run_cli("seed-motion jump_high --robustness-check --start /nonexistent/m0.json");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("diverse: error: /nonexistent/m0.json: cannot read the parameter file"),
            std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace diverse
