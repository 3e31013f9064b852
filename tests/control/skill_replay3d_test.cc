// The 3D jumps as skill files (skills/jump3d.toml, skills/robot_jump.toml): each committed
// task's input motion gives the rollout it gave under the C++ controller the tasks ran
// before ("jump3d", with the keys landing_control and asymmetric; the robot's also
// joint_space_extend and extend_root_kd = 400), to the last bit: the fingerprints of its
// qpos and ctrl at every step, at the task's timestep and at half of it, were taken from
// that controller, and its rollouts and the engine's compared equal step by step, before
// it was removed. The skill's check binds it to the character.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "physics/rollout.h"
#include "support/fingerprint.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

using test_files::fingerprint;

struct Pinned {
  double scale;
  int steps;
  uint64_t qpos, ctrl;
};

void expect_rollouts(const std::string& task, const std::vector<Pinned>& pinned) {
  const Task t = load_task(kTasks + task + ".toml");
  ASSERT_EQ(t.controller, "skill");
  const TaskEvaluator ev(t);
  const ParameterSet m0 = ev.load_parameters(t.m0);
  for (const Pinned& p : pinned) {
    StepRecorder record;
    EvaluationOptions o;
    o.timestep_scale = p.scale;
    o.recorder = &record;
    auto worker = ev.make_worker();
    const Evaluation e = ev.evaluate(m0.values(), *worker, o);
    EXPECT_EQ(e.constraint, 0.0) << task << " x" << p.scale;
    EXPECT_EQ(record.steps(), p.steps) << task << " x" << p.scale;
    EXPECT_EQ(fingerprint(record.qpos), p.qpos) << task << " x" << p.scale << ": qpos 0x" << std::hex << fingerprint(record.qpos);
    EXPECT_EQ(fingerprint(record.ctrl), p.ctrl) << task << " x" << p.scale << ": ctrl 0x" << std::hex << fingerprint(record.ctrl);
  }
}

TEST(SkillReplay3d, TheHumansJumpBackwardsAsUnderJump3d) {
  expect_rollouts("jump_backwards", {{1.0, 1167, 0x089cc61c4f174273ull, 0xb932be30372be3bdull},
                                     {0.5, 2335, 0xf9f76b28814a5894ull, 0x24f02b2311a3f18bull}});
}

TEST(SkillReplay3d, TheRobotsJumpAsUnderJump3d) {
  expect_rollouts("robot_jump", {{1.0, 1548, 0x1a00ab4381584f2bull, 0xe2e351892ca87971ull},
                                 {0.5, 2816, 0xc3f4e1e3381ef257ull, 0xd30b5c385981d1c5ull}});
}

// The task's check binds its skill to the character: a free-root skill refuses the planar
// human with the skill file's line.
TEST(SkillReplay3d, TheChecksBindTheSkillToTheCharacter) {
  const Task human3d = load_task(kTasks + "jump_backwards.toml");
  const TaskEvaluator planar(load_task(kTasks + "jump_high.toml"));
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
