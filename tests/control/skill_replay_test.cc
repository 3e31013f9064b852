// The 2D jumps as skill files (skills/): each committed input motion gives the same rollout
// under the skill engine (control/skill_controller.h) as under the "jump2d" controller it
// replaces, the same qpos at every step to the last bit, at the task's timestep and at half
// of it, and the same parameter names in the same order.
#include <gtest/gtest.h>

#include <string>

#include "physics/rollout.h"
#include "support/task_variant.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

struct Case {
  const char* task;
  const char* skill;  // the [controller] table of the task under the engine
};

// The jump2d task file's [controller] table replaced by `controller`.
Task under(const Case& c, const std::string& controller) {
  const std::string source = DIVERSE_SOURCE_DIR;
  const auto file = test_files::task_variant(
      c.task, std::string("skill_replay_") + c.task + (controller.empty() ? "_jump2d" : "_skill"),
      controller.empty() ? std::vector<std::string>{}
                         : std::vector<std::string>{"type =", "landing_control =", "landing_height =", "tuck_time =",
                                                    "open_time =", "open_turn =", "balance_kp =", "balance_kd =",
                                                    "balance_max_force =", "stance_landing =", "stand_after =",
                                                    "landing_at_touchdown =", "landing_reach =", "crouch_lean =",
                                                    "level_feet ="},
      {{"controller", controller}});
  return load_task(file.string());
}

class SkillReplay : public ::testing::TestWithParam<Case> {};

TEST_P(SkillReplay, SameQposAtEveryStepAsJump2d) {
  const Case c = GetParam();
  const std::string skills = std::string(DIVERSE_SOURCE_DIR) + "/skills/";
  const Task old_task = under(c, "");
  ASSERT_EQ(old_task.controller, "jump2d");
  const Task new_task = under(c, "skill = \"" + skills + c.skill);
  const TaskEvaluator old_eval(old_task), new_eval(new_task);
  // The same parameters, by name and in order.
  const ParameterSet old_params = old_eval.parameters(), new_params = new_eval.parameters();
  ASSERT_EQ(old_params.size(), new_params.size());
  for (size_t i = 0; i < old_params.specs().size(); ++i) {
    const ParamSpec& a = old_params.specs()[i];
    const ParamSpec& b = new_params.specs()[i];
    EXPECT_EQ(a.name, b.name) << i;
    EXPECT_EQ(a.lower, b.lower) << a.name;
    EXPECT_EQ(a.upper, b.upper) << a.name;
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
    ASSERT_GT(old_record.steps(), 100);
    ASSERT_EQ(old_record.qpos.size(), new_record.qpos.size()) << "timestep x" << scale;
    size_t first = old_record.qpos.size();
    for (size_t i = 0; i < old_record.qpos.size() && first == old_record.qpos.size(); ++i) {
      if (old_record.qpos[i] != new_record.qpos[i]) first = i;
    }
    EXPECT_EQ(first, old_record.qpos.size()) << "timestep x" << scale << ": qpos differs first at step "
                                             << first / static_cast<size_t>(old_record.nq);
    EXPECT_TRUE(old_record.ctrl == new_record.ctrl) << "timestep x" << scale;
    EXPECT_EQ(a.constraint, b.constraint);
    for (size_t p = 0; p < a.phases.begin.size(); ++p) EXPECT_EQ(a.phases.begin[p], b.phases.begin[p]) << p;
    EXPECT_EQ(a.phases.names, b.phases.names);
  }
}

INSTANTIATE_TEST_SUITE_P(Jumps, SkillReplay,
                         ::testing::Values(Case{"backflip", "backflip.toml\""},
                                           Case{"jump_forward", "jump_forward.toml\""},
                                           Case{"jump_over", "jump_forward.toml\""},
                                           Case{"jump_high", "jump_high.toml\""},
                                           Case{"jump_onto",
                                                "jump2d.toml\"\nlanding_height = 0.5\n"
                                                "balance = { kp = 4000.0, kd = 800.0, max_force = 800.0 }"}),
                         [](const ::testing::TestParamInfo<Case>& param) { return std::string(param.param.task); });

}  // namespace
}  // namespace diverse
