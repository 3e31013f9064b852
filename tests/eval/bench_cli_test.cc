// `diverse bench`: a task's input motion and a free-root character standing both report the
// rollout against raw mj_step on the same inputs; what it cannot measure is a one-line error.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "support/cli.h"

namespace diverse {
namespace {

using cli_test::run_cli;
const std::string kCharacters = std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/";

TEST(BenchCli, AFreeRootCharacterStandingIsMeasuredAgainstRawSteps) {
  const cli_test::CliResult r = run_cli("bench --character " + kCharacters + "robot3d.toml --seconds 0.2 --json");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["steps_per_rollout"], 1500);  // 3 s standing at 2 ms
  EXPECT_GT(j["raw_mj_step_steps_per_second"].get<double>(), 0.0);
  EXPECT_GT(j["rollout_steps_per_second"].get<double>(), 0.0);
  const double ratio = j["rollout_over_raw"].get<double>();
  EXPECT_GT(ratio, 0.0);
  EXPECT_LT(ratio, 10.0);  // a ratio of two rates of the same physics, not a timing claim
}

TEST(BenchCli, APlanarCharacterIsMeasuredOnATaskInstead) {
  const cli_test::CliResult r = run_cli("bench --character " + kCharacters + "human2d.toml --seconds 0.2");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(r.output, "diverse: error: " + kCharacters +
                          "human2d.toml: root.kind: expected a free root for stance control (planar characters "
                          "are measured on a task: diverse bench TASK)\n");
}

}  // namespace
}  // namespace diverse
