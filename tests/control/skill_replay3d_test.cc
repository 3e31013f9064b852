// The 3D jumps as skill files (skills/jump3d.toml, skills/robot_jump.toml): each committed
// task, which names its skill, gives its input motion the same rollout under the skill
// engine (control/skill_controller.h) as under the "jump3d" controller with the keys the
// task gave it before: the same qpos and ctrl at every step to the last bit, at the task's
// timestep and at half of it, the same phase times, and the same parameter names, ranges
// and order (so the committed input motions and runs resume unchanged).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <string>

#include "core/error.h"
#include "physics/rollout.h"
#include "support/text_files.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

// The task file with its [controller] table replaced by jump3d's keys, paths absolute.
std::string jump3d_variant(const std::string& task, const std::string& keys) {
  const std::string dir = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";
  std::string text = test_files::read_text(dir + task + ".toml");
  const auto from = text.find("[controller]\n"), to = text.find("\n[", from + 1);
  text.replace(from, to - from, "[controller]\ntype = \"jump3d\"\n" + keys);
  for (const char* key : {"character = \"", "m0 = \"", "base = \""}) {
    const auto at = text.find(key);
    if (at != std::string::npos) text.insert(at + std::string(key).size(), dir);
  }
  const auto file = std::filesystem::temp_directory_path() / ("diverse_jump3d_" + task + "_" + std::to_string(::getpid()) + ".toml");
  test_files::write_text(file.string(), text);
  return file.string();
}

void expect_same_rollouts(const Task& old_task, const Task& new_task) {
  const TaskEvaluator old_eval(old_task), new_eval(new_task);
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

TEST(SkillReplay3d, TheHumansJumpBackwardsAsUnderJump3d) {
  const Task old_task = load_task(jump3d_variant("jump_backwards", "landing_control = true\nasymmetric = true\n"));
  ASSERT_EQ(old_task.controller, "jump3d");
  const Task new_task = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_backwards.toml");
  ASSERT_EQ(new_task.controller, "skill");
  expect_same_rollouts(old_task, new_task);
}

TEST(SkillReplay3d, TheRobotsJumpAsUnderJump3d) {
  const Task old_task = load_task(jump3d_variant(
      "robot_jump", "landing_control = true\nasymmetric = true\njoint_space_extend = true\nextend_root_kd = 400.0\n"));
  ASSERT_EQ(old_task.controller, "jump3d");
  const Task new_task = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/robot_jump.toml");
  ASSERT_EQ(new_task.controller, "skill");
  expect_same_rollouts(old_task, new_task);
}

// The task's check binds its skill to the character: a free-root skill refuses the planar
// human with the skill file's line.
TEST(SkillReplay3d, TheChecksBindTheSkillToTheCharacter) {
  const Task human3d = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_backwards.toml");
  const TaskEvaluator planar(load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml"));
  try {
    human3d.controller_type->check(planar.body(), *human3d.controller_config, human3d.file);
    ADD_FAILURE() << "a free-root skill accepted the planar human";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("skills/jump3d.toml: line 10: root: expected a character with a free root, but the character "),
              std::string::npos)
        << e.what();
  }
  const TaskEvaluator own(human3d);  // and accepts its own
  EXPECT_EQ(own.parameters().size(), 145u);
}

}  // namespace
}  // namespace diverse
