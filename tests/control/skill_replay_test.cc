// The 2D jumps as skill files (skills/): each committed task, which names its skill, gives
// its input motion the same rollout under the skill engine (control/skill_controller.h) as
// under the "jump2d" controller with the keys the task gave it before
// (support/jump2d_variant.h): the same qpos at every step to the last bit, at the task's
// timestep and at half of it, the same phase times, and the same parameter names in the
// same order.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <string>

#include "physics/rollout.h"
#include "support/jump2d_variant.h"
#include "support/text_files.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

struct Case {
  const char* task;
};
class SkillReplay : public ::testing::TestWithParam<Case> {};

// The two tasks give the input motion of the first the same parameters and the same
// rollout, step by step, at the task's timestep and at half of it.
void expect_same_rollouts(const Task& old_task, const Task& new_task) {
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

TEST_P(SkillReplay, SameQposAtEveryStepAsJump2d) {
  const Case c = GetParam();
  const Task old_task = load_task(test_files::jump2d_variant(c.task, std::string("replay_") + c.task, {}, {}).string());
  ASSERT_EQ(old_task.controller, "jump2d");
  const Task new_task = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/" + c.task + ".toml");
  ASSERT_EQ(new_task.controller, "skill");
  expect_same_rollouts(old_task, new_task);
}

// Another character: the tailwalker's leap (examples/own-character/), which names "jump2d"
// with the paper's keys, under skills/jump2d.toml.
TEST(SkillReplay, TheTailwalkersLeapUnderThePapersJump) {
  const std::string dir = std::string(DIVERSE_SOURCE_DIR) + "/examples/own-character/";
  std::string text = test_files::read_text(dir + "leap.toml");
  const auto from = text.find("[controller]\n"), to = text.find("\n[", from + 1);
  text.replace(from, to - from, "[controller]\nskill = \"" + std::string(DIVERSE_SOURCE_DIR) + "/skills/jump2d.toml\"\n");
  for (const char* key : {"character = \"", "m0 = \"", "base = \""}) {
    const auto at = text.find(key);
    text.insert(at + std::string(key).size(), dir);
  }
  const auto file = std::filesystem::temp_directory_path() / ("diverse_leap_skill_" + std::to_string(::getpid()) + ".toml");
  test_files::write_text(file.string(), text);
  const Task old_task = load_task(dir + "leap.toml");
  ASSERT_EQ(old_task.controller, "jump2d");
  expect_same_rollouts(old_task, load_task(file.string()));
}

INSTANTIATE_TEST_SUITE_P(Jumps, SkillReplay,
                         ::testing::Values(Case{"backflip"}, Case{"jump_forward"}, Case{"jump_over"},
                                           Case{"jump_high"}, Case{"jump_onto"}),
                         [](const ::testing::TestParamInfo<Case>& param) { return std::string(param.param.task); });

}  // namespace
}  // namespace diverse
