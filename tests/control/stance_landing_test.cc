// The landing by stance control (skills/jump_forward.toml: the land phase's `stance`
// module with stand_after = 0, control/module_stance.h): the land phase run by stance
// control, then standing up. On jump_forward's input motion found under the default
// balance servo and without the crouch's lean
// (tests/control/data/jump_forward.default_servo.m0.json, under the task with its servo
// and lean set back): it still meets the task at both timesteps, and it holds pushes
// forward 0.3 to 0.9 s after touch-down, where the paper's land phase (skills/jump2d.toml
// with jump_forward's landing aim: PD toward the land pose plus J^T balance) does not even
// come to rest balanced without a push. Bad settings of the module are refused with the
// task file's field.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "support/task_errors.h"
#include "support/skill_variant.h"
#include "support/task_variant.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

// jump_forward.toml with `lines` at the top of its [controller] table.
std::string variant(const std::string& name, const std::string& lines) {
  return test_files::task_variant("jump_forward", "stance_landing_" + name, {}, {{"controller", lines}}).string();
}

// The servo of the start and the crouch as the input motion was found with it.
const char* kDefaultServo =
    "balance = { kp = 1500.0, kd = 300.0, max_force = 400.0 }\n"
    "lean = { kp = 1500.0, kd = 300.0, max_force = 400.0, lean = 0.0 }";

EvaluationOptions judged() {
  EvaluationOptions o;
  o.samples_per_phase = 0;
  o.half_timestep_check = true;
  return o;
}

TEST(StanceLanding, MeetsTheTaskAndHoldsForwardPushesAfterTouchdown) {
  const Task paper_task = load_task(test_files::task_variant(
                                        "jump_forward", "stance_landing_paper", {"skill ="},
                                        {{"controller", test_files::skill_line("skills/jump2d.toml") +
                                                            "\nlanding = { at_touchdown = true, reach = 0.05 }"}})
                                        .string());
  const Task stance_task = load_task(variant("stance", kDefaultServo));
  const TaskEvaluator paper(paper_task), stance(stance_task);
  const ParameterSet m0 = paper.load_parameters(std::string(DIVERSE_SOURCE_DIR) +
                                                "/tests/control/data/jump_forward.default_servo.m0.json");
  auto pw = paper.make_worker();
  auto sw = stance.make_worker();
  const Evaluation p0 = paper.evaluate(m0.values(), *pw, judged());
  const Evaluation s0 = stance.evaluate(m0.values(), *sw, judged());
  // Under the paper's land phase this input motion comes down on its heels with its
  // capture point behind them and never comes to rest balanced (task/support.h): a fall.
  EXPECT_TRUE(p0.fell) << p0.constraint;
  ASSERT_EQ(s0.constraint, 0.0) << s0.summary.fall_reason;
  // The same jump up to touch-down; the landing differs.
  EXPECT_EQ(s0.phases.landing(), p0.phases.landing());
  EXPECT_EQ(s0.summary.touchdown_feet_x, p0.summary.touchdown_feet_x);
  EXPECT_NE(s0.summary.feet_x, p0.summary.feet_x);

  int paper_held = 0, stance_held = 0;
  for (double after : {0.3, 0.5, 0.7, 0.9}) {
    EvaluationOptions o = judged();
    o.push.time = p0.phases.landing() + after;
    o.push.dv = {0.3, 0, 0};
    const Evaluation p = paper.evaluate(m0.values(), *pw, o);
    const Evaluation s = stance.evaluate(m0.values(), *sw, o);
    ASSERT_GE(s.push_time, 0);
    std::printf("push 0.3 m/s forward %.1f s after touch-down: paper C %g (%s), stance C %g (%s)\n", after,
                p.constraint, p.summary.fall_reason.c_str(), s.constraint, s.summary.fall_reason.c_str());
    paper_held += p.constraint == 0 && !p.failed;
    stance_held += s.constraint == 0 && !s.failed;
  }
  EXPECT_GE(stance_held, 3);
  EXPECT_LT(paper_held, stance_held);
}

TEST(StanceLanding, BadSettingsAreRefused) {
  auto refused = [](const std::string& lines, const std::string& expected) {
    test_files::expect_task_refused(variant("bad", lines), expected);
  };
  refused("stance = { stand_after = -2 }", "controller.stance.stand_after: expected a number in [-1, ");
  refused("stance = { stand_after = \"soon\" }", "controller.stance.stand_after: expected a number");
  // A stand-up over no time at all divides by zero.
  refused("stance = { stand_duration = 0 }", "controller.stance.stand_duration: expected a number in [0.05, ");
  refused("stance = { stand_duration = -0.5 }", "controller.stance.stand_duration: expected a number in [0.05, ");
}

}  // namespace
}  // namespace diverse
