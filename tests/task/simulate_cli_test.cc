// `diverse simulate` on a motion that never gets off the ground: the phases it never
// reached are reported as such, not with a made-up time.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "support/cli.h"
#include "task/evaluate.h"
#include "support/scratch.h"

namespace diverse {
namespace {

TEST(SimulateCli, PhasesNeverReachedAreSaidToBe) {
  const std::string task_file = std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml";
  const TaskEvaluator ev(load_task(task_file));
  // Every parameter at the bottom of its range: weak gains, a short crouch; the
  // character collapses before it can take off.
  const ParameterSet lowest = ev.parameters();
  nlohmann::json j;
  for (int i = 0; i < lowest.size(); ++i) {
    j["parameters"][lowest.specs()[static_cast<size_t>(i)].name] = lowest.values()[static_cast<size_t>(i)];
  }
  const auto dir = test_files::scratch_dir("simulate_cli_test");
  std::filesystem::create_directories(dir);
  const auto params = dir / "lowest.json";
  std::ofstream(params) << j.dump(1);

  const auto r = cli_test::run_cli("simulate " + task_file + " --params " + params.string() +
                                   " --out " + (dir / "out").string() + " --no-film");
  EXPECT_NE(r.output.find("fall "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("phase rise    not reached"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("phase land    not reached"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("-1.000"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("phase start   begins at 0.000 s"), std::string::npos) << r.output;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace diverse
