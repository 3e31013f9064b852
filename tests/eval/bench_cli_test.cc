// `diverse bench`: a task's input motion and a free-root character standing both report the
// rollout against raw mj_step on the same inputs; what it cannot measure is a one-line error.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "eval/throughput.h"
#include "support/cli.h"

namespace diverse {
namespace {

using cli_test::run_cli;
const std::string kCharacters = std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/";

// A figure's spread over rounds: median and quartiles by linear interpolation, rounds kept
// in their order.
TEST(Spread, MedianQuartilesAndRangeOfTheRounds) {
  const Spread s = Spread::of({5, 1, 4, 2, 3});
  EXPECT_EQ(s.rounds, (std::vector<double>{5, 1, 4, 2, 3}));
  EXPECT_DOUBLE_EQ(s.median, 3);
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 5);
  EXPECT_DOUBLE_EQ(s.q1, 2);
  EXPECT_DOUBLE_EQ(s.q3, 4);
  const Spread even = Spread::of({10, 20, 30, 40});
  EXPECT_DOUBLE_EQ(even.median, 25);
  EXPECT_DOUBLE_EQ(even.q1, 17.5);
  EXPECT_DOUBLE_EQ(even.q3, 32.5);
  const Spread one = Spread::of({0.9});
  EXPECT_DOUBLE_EQ(one.median, 0.9);
  EXPECT_DOUBLE_EQ(one.q1, 0.9);
  EXPECT_DOUBLE_EQ(one.max, 0.9);
}

// Every round's figures are in the report, and the median and spread are theirs.
void expect_spread_of_rounds(const nlohmann::json& s, int rounds) {
  ASSERT_TRUE(s.contains("rounds")) << s.dump();
  const std::vector<double> values = s["rounds"].get<std::vector<double>>();
  ASSERT_EQ(static_cast<int>(values.size()), rounds);
  const Spread expected = Spread::of(values);
  EXPECT_DOUBLE_EQ(s["median"].get<double>(), expected.median);
  EXPECT_DOUBLE_EQ(s["min"].get<double>(), expected.min);
  EXPECT_DOUBLE_EQ(s["max"].get<double>(), expected.max);
  EXPECT_LE(s["q1"].get<double>(), s["median"].get<double>());
  EXPECT_LE(s["median"].get<double>(), s["q3"].get<double>());
  for (double v : values) EXPECT_GT(v, 0.0);
}

TEST(BenchCli, ATaskIsMeasuredInInterleavedRoundsWithMedianAndSpread) {
  const cli_test::CliResult r = run_cli("bench jump_high --rounds 3 --seconds 0.05 --threads 2 --batch 6 --json");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["rounds"], 3);
  EXPECT_EQ(j["threads"], 2);
  expect_spread_of_rounds(j["rollout_over_raw_rounds"], 3);
  expect_spread_of_rounds(j["parallel_speedup_rounds"], 3);
  expect_spread_of_rounds(j["parallel_speedup_cpu_span_rounds"], 3);
  expect_spread_of_rounds(j["cpu_share_n_threads"], 3);
  EXPECT_DOUBLE_EQ(j["rollout_over_raw"].get<double>(), j["rollout_over_raw_rounds"]["median"].get<double>());
  EXPECT_DOUBLE_EQ(j["parallel_speedup"].get<double>(), j["parallel_speedup_rounds"]["median"].get<double>());
  // Shares of cores and ratios of two rates of the same work, not timing claims.
  EXPECT_LE(j["cpu_share_n_threads"]["max"].get<double>(), 1.05);
  EXPECT_LT(j["rollout_over_raw_rounds"]["max"].get<double>(), 10.0);
}

TEST(BenchCli, AFreeRootCharacterStandingIsMeasuredAgainstRawSteps) {
  const cli_test::CliResult r = run_cli("bench --character " + kCharacters + "robot3d.toml --seconds 0.1 --rounds 2 --json");
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["steps_per_rollout"], 1500);  // 3 s standing at 2 ms
  EXPECT_GT(j["raw_mj_step_steps_per_second"].get<double>(), 0.0);
  EXPECT_GT(j["rollout_steps_per_second"].get<double>(), 0.0);
  const double ratio = j["rollout_over_raw"].get<double>();
  EXPECT_GT(ratio, 0.0);
  EXPECT_LT(ratio, 10.0);  // a ratio of two rates of the same physics, not a timing claim
  expect_spread_of_rounds(j["rollout_over_raw_rounds"], 2);
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
