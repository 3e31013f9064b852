// The committed input walks (tasks/silly_walk.m0.json, tasks/robot_silly_walk.m0.json),
// simulated fresh: each walks its 30 steps without a fall and meets its task (C = 0) at
// the task's timestep and at half of it, keeps every net joint torque (motor plus
// damping) within its limit at every step, replays exactly, and some of its
// neighbourhood in parameter space meets the task too.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "physics/drive.h"
#include "task/evaluate.h"
#include "task/seed_motion.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

void expect_walk_meets(const std::string& name, double timestep) {
  Task task = load_task(kTasks + name + ".toml");
  ASSERT_TRUE(std::filesystem::exists(task.m0)) << task.m0;
  task.simulation.timestep = timestep;
  const TaskEvaluator ev(task);
  const ParameterSet p = ev.load_parameters(task.m0);
  const auto worker = ev.make_worker();
  StepRecorder record;
  EvaluationOptions options;
  options.recorder = &record;
  const Evaluation e = ev.evaluate(p.values(), *worker, options);
  ASSERT_FALSE(e.failed) << e.failure;
  EXPECT_FALSE(e.fell) << name << ": " << e.summary.fall_reason;
  EXPECT_EQ(e.constraint, 0) << name;
  EXPECT_EQ(e.summary.walk.steps.size(), 30u) << name;
  for (size_t i = 10; i < e.summary.walk.steps.size(); ++i) {
    const WalkStep& s = e.summary.walk.steps[i];
    EXPECT_LE(std::fabs(s.forward - task.walk.forward_center), task.walk.forward_half_width) << name << " step " << i;
    EXPECT_LE(std::fabs(s.lateral - task.walk.lateral_center), task.walk.lateral_half_width) << name << " step " << i;
    EXPECT_LE(s.tilt, task.walk.max_tilt_deg * M_PI / 180) << name << " step " << i;
  }
  mjModel* plain = mj_copyModel(nullptr, ev.model().get());
  const NetTorqueCheck check = check_net_torque(plain, record, driven_joints(plain));
  mj_deleteModel(plain);
  EXPECT_EQ(check.steps, record.steps());
  EXPECT_LE(check.worst_excess, 0.0) << name << ": step " << check.worst_step << ", joint " << check.worst_joint;
  plain = mj_copyModel(nullptr, ev.model().get());
  EXPECT_EQ(replay(plain, record), 0.0) << name;
  mj_deleteModel(plain);
}

TEST(WalkM0, HumanMeetsItsTask) { expect_walk_meets("silly_walk", 0); }
TEST(WalkM0, HumanMeetsItsTaskAtHalfTheTimestep) { expect_walk_meets("silly_walk", 0.001); }
TEST(WalkM0, RobotMeetsItsTask) { expect_walk_meets("robot_silly_walk", 0); }
TEST(WalkM0, RobotMeetsItsTaskAtHalfTheTimestep) { expect_walk_meets("robot_silly_walk", 0.001); }

// Half or more of the input walks' perturbations at a normalized step of 0.02 meet the task,
// at both timesteps (the committed walks: 28 and 18 of 32; `diverse seed-motion TASK
// --robustness-check`).
TEST(WalkM0, HalfOfTheNeighbourhoodMeetsTheTask) {
  for (const char* name : {"silly_walk", "robot_silly_walk"}) {
    const Task task = load_task(kTasks + name + std::string(".toml"));
    const TaskEvaluator ev(task);
    const RobustnessReport r = measure_robustness(task, ev.load_parameters(task.m0), {0.02}, 32, 2);
    EXPECT_EQ(r.constraint, 0) << name;
    EXPECT_EQ(r.constraint_fine, 0) << name;
    EXPECT_GE(r.levels[0].met, 16) << name << ": of 32 perturbations at 0.02";
  }
}

}  // namespace
}  // namespace diverse
