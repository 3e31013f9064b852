// The friction cone of the contacts (`[simulation] friction_cone`, task/task.h; the planar
// human's model asks for the elliptic one). Under MuJoCo's pyramidal cone the friction
// coefficient enters every contact's constraint rows, so a floor of friction 1.5 instead
// of 1 changed the high jump's push-off, which never slides: it took off pitched 10
// degrees further and its landing fell. Under the elliptic cone the same jump takes off
// alike on both floors and lands on each.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

Evaluation jump(const Task& task, double friction) {
  const TaskEvaluator ev(task);
  auto worker = ev.make_worker();
  EvaluationOptions o;
  o.samples_per_phase = 0;
  o.friction_scale = friction;
  return ev.evaluate(ev.load_parameters(task.m0).values(), *worker, o);
}

TEST(FrictionCone, ThePlanarHumanHasTheEllipticCone) {
  const Task task = load_task(kTasks + "jump_high.toml");
  EXPECT_TRUE(task.simulation.friction_cone.empty()) << "the model's own";
  EXPECT_EQ(TaskEvaluator(task).model().get()->opt.cone, mjCONE_ELLIPTIC);
  Task pyramidal = task;
  pyramidal.simulation.friction_cone = "pyramidal";
  EXPECT_EQ(TaskEvaluator(pyramidal).model().get()->opt.cone, mjCONE_PYRAMIDAL);
  // The override leaves the rest of <option> as it was.
  EXPECT_EQ(TaskEvaluator(pyramidal).model().get()->opt.timestep, TaskEvaluator(task).model().get()->opt.timestep);
}

// The high jump's input motion found under the default balance servo
// (tests/task/data/jump_high_default_servo.toml), found under the elliptic cone from the
// one found under the pyramidal cone.
TEST(FrictionCone, AFloorOfOtherFrictionLeavesAPushOffThatDoesNotSlideAlone) {
  const Task elliptic = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tests/task/data/jump_high_default_servo.toml");
  Task pyramidal = elliptic;
  pyramidal.simulation.friction_cone = "pyramidal";
  const double deg = 180 / M_PI;

  const Evaluation e1 = jump(elliptic, 1.0), e15 = jump(elliptic, 1.5), e08 = jump(elliptic, 0.8);
  for (const Evaluation* e : {&e1, &e15, &e08}) {
    EXPECT_EQ(e->constraint, 0.0) << e->summary.fall_reason;
    EXPECT_NEAR(e->summary.rotation_flight * deg, e1.summary.rotation_flight * deg, 1.5);
    EXPECT_NEAR(e->summary.peak_com_z, e1.summary.peak_com_z, 0.005);
  }

  const Evaluation p1 = jump(pyramidal, 1.0), p15 = jump(pyramidal, 1.5);
  EXPECT_EQ(p1.constraint, 0.0);
  EXPECT_GT(std::abs(p15.summary.rotation_flight - p1.summary.rotation_flight) * deg, 8.0);
  EXPECT_TRUE(p15.fell) << "its landing fell on the floor of friction 1.5";
}

}  // namespace
}  // namespace diverse
