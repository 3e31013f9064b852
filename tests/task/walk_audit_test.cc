// The walk audit (task/walk_audit.h) finds a walk's steps from foot contacts alone, without
// the controller: on both committed input walks it counts the same 30 alternating steps as
// the task's own observer, at the same times and with the same lengths, and finds no broken
// rule; a record cut short, a stricter task and a walker that falls are caught.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "physics/rollout.h"
#include "task/evaluate.h"
#include "task/task.h"
#include "task/walk_audit.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

struct Recorded {
  Evaluation evaluation;
  StepRecorder record;
};

Recorded walk(const TaskEvaluator& ev, const ParameterSet& p) {
  Recorded r;
  EvaluationOptions options;
  options.samples_per_phase = 0;
  options.recorder = &r.record;
  const auto worker = ev.make_worker();
  r.evaluation = ev.evaluate(p.values(), *worker, options);
  return r;
}

// `footprints`: the range of the evaluated steps' lengths from footprint to footprint,
// measured at the time of writing.
void expect_agrees(const std::string& name, std::array<double, 2> footprints) {
  const TaskEvaluator ev(load_task(kTasks + name + ".toml"));
  const Recorded r = walk(ev, ev.load_parameters(ev.task().m0));
  ASSERT_FALSE(r.evaluation.fell) << r.evaluation.summary.fall_reason;
  const WalkAudit a = audit_walk(ev.model().get(), r.record, ev.body(), ev.task().walk);
  EXPECT_TRUE(a.violations.empty()) << a.violations.front();
  EXPECT_FALSE(a.fell) << a.fall_body;
  const auto& steps = r.evaluation.summary.walk.steps;
  ASSERT_EQ(a.steps.size(), steps.size());
  ASSERT_EQ(a.steps.size(), 30u);
  const double dt = r.record.timestep;
  ASSERT_GT(dt, 0);
  for (size_t k = 0; k < steps.size(); ++k) {
    EXPECT_EQ(a.steps[k].leg, steps[k].leg) << k;
    EXPECT_NEAR(a.steps[k].time, steps[k].time, 1.5 * dt) << k;
    // The positions are read one simulation step apart at most: a foot moves millimetres.
    EXPECT_NEAR(a.steps[k].forward, steps[k].forward, 0.01) << k;
    EXPECT_NEAR(a.steps[k].lateral, steps[k].lateral, 0.01) << k;
  }
  EXPECT_GE(a.forward_min, ev.task().walk.forward_center - ev.task().walk.forward_half_width);
  EXPECT_LE(a.forward_max, ev.task().walk.forward_center + ev.task().walk.forward_half_width);
  EXPECT_LE(a.max_tilt, ev.task().walk.max_tilt_deg * M_PI / 180);
  // The task measures steps from footprint to footprint.
  ASSERT_TRUE(ev.task().walk.from_footprint);
  for (size_t k = 0; k < a.steps.size(); ++k) EXPECT_EQ(a.steps[k].forward, a.steps[k].footprint_forward) << k;
  // From the other foot where it is at the touch-down, the steps are shorter: the other
  // foot slid and rolled forward while it was down (task/foot_slip.h).
  TaskWalk from_foot = ev.task().walk;
  from_foot.from_footprint = false;
  const WalkAudit now = audit_walk(ev.model().get(), r.record, ev.body(), from_foot);
  ASSERT_EQ(now.steps.size(), a.steps.size());
  for (int k = ev.task().walk.settle_steps; k < 30; ++k)
    EXPECT_GT(a.steps[static_cast<size_t>(k)].footprint_forward, now.steps[static_cast<size_t>(k)].forward + 0.03) << k;
  EXPECT_NEAR(a.footprint_forward_min, footprints[0], 0.005);
  EXPECT_NEAR(a.footprint_forward_max, footprints[1], 0.005);

  // A stricter task: steps of 2 +- 0.1 m are not what this walk does.
  TaskWalk strict = ev.task().walk;
  strict.forward_center = 2.0;
  strict.forward_half_width = 0.1;
  const WalkAudit b = audit_walk(ev.model().get(), r.record, ev.body(), strict);
  ASSERT_EQ(b.violations.size(), 20u);  // every evaluated step
  EXPECT_NE(b.violations.front().find("step 11: forward"), std::string::npos) << b.violations.front();

  // The record cut after its 25th step's touch-down.
  StepRecorder cut = r.record;
  const size_t keep = static_cast<size_t>(a.steps[24].sim_step + 1);
  cut.ctrl.resize(keep * static_cast<size_t>(cut.nu));
  cut.qpos.resize(keep * static_cast<size_t>(cut.nq));
  const WalkAudit c = audit_walk(ev.model().get(), cut, ev.body(), ev.task().walk);
  EXPECT_EQ(c.steps.size(), 25u);
  ASSERT_FALSE(c.violations.empty());
  EXPECT_EQ(c.violations.front(), "took 25 steps, the task asks for 30");
}

TEST(WalkAudit, HumanInputWalkAgreesWithTheTask) { expect_agrees("silly_walk", {0.687, 0.723}); }
TEST(WalkAudit, RobotInputWalkAgreesWithTheTask) { expect_agrees("robot_silly_walk", {1.228, 1.476}); }

TEST(WalkAudit, FindsAFall) {
  const TaskEvaluator ev(load_task(kTasks + "silly_walk.toml"));
  ParameterSet p = ev.load_parameters(ev.task().seed.base);
  // Torso bent forward to its limit: the walker falls within a few steps.
  p.set("lift.torso.waist", p.specs()[static_cast<size_t>(p.find("lift.torso.waist"))].lower);
  p.set("strike.torso.waist", p.specs()[static_cast<size_t>(p.find("strike.torso.waist"))].lower);
  const Recorded r = walk(ev, p);
  ASSERT_TRUE(r.evaluation.fell);
  const WalkAudit a = audit_walk(ev.model().get(), r.record, ev.body(), ev.task().walk);
  // The rollout ends at the fall; the audit sees the same or fewer steps and says so.
  EXPECT_LE(a.steps.size(), r.evaluation.summary.walk.steps.size());
  ASSERT_FALSE(a.violations.empty());
  bool short_walk = false;
  for (const std::string& v : a.violations) short_walk |= v.rfind("took ", 0) == 0;
  EXPECT_TRUE(short_walk);
  if (r.evaluation.summary.fall_reason.find("touched") != std::string::npos) {
    EXPECT_TRUE(a.fell);
    EXPECT_NEAR(a.fall_time, r.evaluation.summary.end_time, 0.01);
  }
}

}  // namespace
}  // namespace diverse
