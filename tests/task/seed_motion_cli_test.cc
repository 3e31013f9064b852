// `diverse seed-motion` keeps the task's m0 file for motions that meet the task: a search
// that falls short writes its best attempt beside it and says how to continue. With
// --robustness-check it measures a motion and its neighbourhood instead of searching.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "io/files.h"
#include "support/cli.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

TEST(SeedMotionCli, AShortSearchThatFailsWritesAPartialFileNotTheM0) {
  const fs::path dir = fs::temp_directory_path() / "diverse_seed_motion_cli_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string source = DIVERSE_SOURCE_DIR;
  // jump_forward's constraints, starting from the hand-authored small in-place jump, which
  // one generation of search cannot turn into a 1 m forward jump.
  write_file_atomic(dir / "short.toml",
                    "name = \"short\"\n"
                    "character = \"" + source + "/assets/characters/human2d.xml\"\n"
                    "metric = \"md\"\n"
                    "variations = 4\n"
                    "m0 = \"short.m0.json\"\n"
                    "[controller]\ntype = \"jump2d\"\n"
                    "[constraints]\nweight = 5000.0\nfall_penalty = 100000.0\nlanding = { center = 1.0, half_width = 0.15 }\n"
                    "[seed]\nbase = \"" + source + "/tasks/base_jump.json\"\ngenerations = 1\n");
  const auto r = cli_test::run_cli("seed-motion " + (dir / "short.toml").string() + " --threads 2");
  EXPECT_NE(r.status, 0) << r.output;
  EXPECT_FALSE(fs::exists(dir / "short.m0.json"));
  ASSERT_TRUE(fs::exists(dir / "short.partial.json")) << r.output;
  EXPECT_GT(read_json(dir / "short.partial.json")["constraint"].get<double>(), 0.0);
  EXPECT_NE(r.output.find("no motion meeting the task was found"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--start " + (dir / "short.partial.json").string()), std::string::npos)
      << r.output;
}

TEST(SeedMotionCli, RobustnessCheckReportsBothTimestepsAndTheNeighbourhood) {
  const auto r = cli_test::run_cli(
      "seed-motion jump_high --robustness-check --check-sigmas 1e-6 0.5 --check-samples 3");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("C = 0 at the task's timestep, 0 with it halved"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("landing spots at the two timesteps differ by 0.0"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("sigma 0.000: 3 of 3 perturbations meet the task (100 %)"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("sigma 0.500: 0 of 3 perturbations meet the task (0 %)"),
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
