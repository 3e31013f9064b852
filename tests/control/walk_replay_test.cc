// The SIMBICON walks as skill files (skills/walk3d.toml, skills/robot_walk3d.toml): each
// walk task, which names its skill, gives its committed input motion the same rollout
// under the skill engine (control/skill_controller.h) as under the "walk3d" controller the
// task named before: the same parameter names, ranges and order, and the same qpos and
// ctrl at every step to the last bit, at the task's timestep and at half of it, the same
// phase times and the same C.
#include <gtest/gtest.h>

#include <string>

#include "physics/rollout.h"
#include "support/task_variant.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

class WalkReplay : public ::testing::TestWithParam<const char*> {};

TEST_P(WalkReplay, SameQposAtEveryStepAsWalk3d) {
  const std::string name = GetParam();
  const Task old_task = load_task(
      test_files::task_variant(name, std::string("walk_replay_") + name, {"skill =", "# SIMBICON walking as"},
                               {{"controller", "type = \"walk3d\""}})
          .string());
  ASSERT_EQ(old_task.controller, "walk3d");
  const Task new_task = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/" + name + ".toml");
  ASSERT_EQ(new_task.controller, "skill");
  ASSERT_TRUE(new_task.walk.enabled);
  const TaskEvaluator old_eval(old_task), new_eval(new_task);
  const ParameterSet old_params = old_eval.parameters(), new_params = new_eval.parameters();
  ASSERT_EQ(old_params.size(), new_params.size());
  for (size_t i = 0; i < old_params.specs().size(); ++i) {
    const ParamSpec& a = old_params.specs()[i];
    const ParamSpec& b = new_params.specs()[i];
    EXPECT_EQ(a.name, b.name) << i;
    EXPECT_EQ(a.lower, b.lower) << a.name;
    EXPECT_EQ(a.upper, b.upper) << a.name;
    EXPECT_EQ(a.unit, b.unit) << a.name;
  }
  const ParameterSet m0 = old_eval.load_parameters(old_task.m0);
  for (double scale : {1.0, 0.5}) {
    StepRecorder old_record, new_record;
    EvaluationOptions o;
    o.timestep_scale = scale;
    o.recorder = &old_record;
    auto ow = old_eval.make_worker();
    const Evaluation a = old_eval.evaluate(m0.values(), *ow, o);
    o.recorder = &new_record;
    auto nw = new_eval.make_worker();
    const Evaluation b = new_eval.evaluate(m0.values(), *nw, o);
    ASSERT_GT(old_record.steps(), 1000);
    EXPECT_EQ(old_record.qpos0, new_record.qpos0) << "timestep x" << scale;
    ASSERT_EQ(old_record.qpos.size(), new_record.qpos.size()) << "timestep x" << scale;
    size_t first = old_record.qpos.size();
    for (size_t i = 0; i < old_record.qpos.size() && first == old_record.qpos.size(); ++i) {
      if (old_record.qpos[i] != new_record.qpos[i]) first = i;
    }
    EXPECT_EQ(first, old_record.qpos.size()) << "timestep x" << scale << ": qpos differs first at step "
                                             << first / static_cast<size_t>(old_record.nq);
    EXPECT_TRUE(old_record.ctrl == new_record.ctrl) << "timestep x" << scale;
    EXPECT_EQ(a.constraint, b.constraint);
    EXPECT_EQ(a.constraint, 0.0) << "the input walk meets its task";
    EXPECT_EQ(a.phases.names, b.phases.names);
    for (size_t p = 0; p < a.phases.begin.size(); ++p) EXPECT_EQ(a.phases.begin[p], b.phases.begin[p]) << p;
  }
}

INSTANTIATE_TEST_SUITE_P(Walks, WalkReplay, ::testing::Values("silly_walk", "robot_silly_walk"),
                         [](const ::testing::TestParamInfo<const char*>& param) { return std::string(param.param); });

}  // namespace
}  // namespace diverse
