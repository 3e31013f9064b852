// A finished run read back, on a small real run directory made with the run's own writers
// (support/jump_run.h: two simulated jumps, M0 and a variation).
#include "finished/run_view.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "io/files.h"
#include "support/jump_run.h"
#include "task/task.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

class RunViewTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One directory per process: CTest runs the tests of this file as separate processes,
    // possibly at the same time.
    dir_ = fs::temp_directory_path() / ("diverse_run_view_test_" + std::to_string(getpid())) / "run";
    test_support::write_jump_run(dir_);
  }

  static void TearDownTestSuite() { fs::remove_all(dir_.parent_path()); }

  static fs::path dir_;
};
fs::path RunViewTest::dir_;

TEST_F(RunViewTest, ReadsTheRunAndSamplesRecordedStates) {
  const RunView run = load_run_view(dir_);
  ASSERT_EQ(run.motions.size(), 2u);
  EXPECT_EQ(run.task_name, "jump_high");
  EXPECT_EQ(run.metric, "md");
  EXPECT_EQ(run.task_note, "");
  // The task file as run.json names it (its landing region: render/run_media.h's test).
  ASSERT_NE(run.task, nullptr);
  EXPECT_EQ(run.task->name, "jump_high");
  EXPECT_EQ(run.task->file, test_support::jump_high_task_file());

  const RunMotion& m = run.motions[1];
  EXPECT_EQ(m.label, "M1");
  EXPECT_EQ(m.model_path, dir_ / "model" / "m1.xml");
  EXPECT_GT(m.duration(), 1.0);
  EXPECT_GT(m.phases.takeoff(), 0.0);  // phase times read from the motion file
  const double dt = m.record.timestep;
  EXPECT_EQ(m.qpos_at(0.0), m.record.qpos0);
  EXPECT_EQ(m.qpos_at(dt), std::vector<double>(m.record.qpos.begin(), m.record.qpos.begin() + m.record.nq));
  EXPECT_EQ(m.qpos_at(1e9), std::vector<double>(m.record.qpos.end() - m.record.nq, m.record.qpos.end()));
  const auto frames = m.sample(30.0);
  EXPECT_EQ(frames.size(), static_cast<std::size_t>(std::floor(m.duration() * 30.0 + 1e-9)) + 1);
  EXPECT_EQ(frames[3], m.qpos_at(0.1));
  const auto slow = m.sample(30.0, 0.5);
  EXPECT_EQ(slow.size(), static_cast<std::size_t>(std::floor(m.duration() * 60.0 + 1e-9)) + 1);
  EXPECT_EQ(slow[6], frames[3]);
  EXPECT_EQ(run.motions[0].status(), run.motions[0].constraint == 0 ? "C = 0, meets the task" : run.motions[0].status());
}

// The motions are still read when the task file is gone; the view says why it has no task.
TEST_F(RunViewTest, ATaskFileThatCannotBeReadLeavesANote) {
  const fs::path dir = dir_.parent_path() / "no_task";
  fs::remove_all(dir);
  fs::copy(dir_, dir, fs::copy_options::recursive);
  const fs::path missing = dir_.parent_path() / "gone.toml";
  nlohmann::json run_file = read_json(dir / "run.json");
  run_file["task_file"] = missing.string();
  write_json_atomic(dir / "run.json", run_file);

  const RunView run = load_run_view(dir);
  EXPECT_EQ(run.motions.size(), 2u);
  EXPECT_EQ(run.task, nullptr);
  EXPECT_NE(run.task_note.find(missing.string()), std::string::npos) << run.task_note;
}

}  // namespace
}  // namespace diverse
