// Walk tasks (task/walk_task.h, task/walk_eval.h): the [walk] table is read strictly and
// must go with a walk controller; the walk constraint penalty follows the task's ranges,
// grades a fall by the steps taken and judges turns from the start's heading; evaluating
// the committed input walks counts 30 alternating steps and stops at the last touch-down,
// meets both tasks, and gives 10 pose samples in each of the 4 states of the 10 evaluated
// strides, in each stride's heading frame; a hop and a fall end the rollout.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "metric/metric.h"
#include "task/constraints.h"
#include "task/evaluate.h"
#include "task/task.h"
#include "task/walk_audit.h"
#include "task/term_foot_slip.h"
#include "task/walk_task.h"

namespace diverse {
namespace {

namespace fs = std::filesystem;
const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

// Walk parameters kept for a test in tests/task/data/.
ParameterSet test_walk(const TaskEvaluator& ev, const std::string& file) {
  return ev.load_parameters(std::string(DIVERSE_SOURCE_DIR) + "/tests/task/data/" + file);
}

// One evaluation of `p` on a worker of its own.
Evaluation evaluate_once(const TaskEvaluator& ev, const ParameterSet& p) {
  const auto worker = ev.make_worker();
  return ev.evaluate(p.values(), *worker);
}

// The walk audit (task/walk_audit.h) of one evaluation of `p`.
WalkAudit audit_once(const TaskEvaluator& ev, const ParameterSet& p) {
  StepRecorder record;
  EvaluationOptions options;
  options.recorder = &record;
  ev.evaluate(p.values(), *ev.make_worker(), options);
  return audit_walk(ev.model().get(), record, ev.body(), ev.task().walk);
}

// The task's steps are the audit's steps: same feet, times and lengths.
void expect_same_steps(const Evaluation& e, const WalkAudit& a) {
  const auto& steps = e.summary.walk.steps;
  ASSERT_GE(a.steps.size(), steps.size());
  for (size_t i = 0; i < steps.size(); ++i) {
    EXPECT_EQ(steps[i].leg, a.steps[i].leg) << "step " << i + 1;
    EXPECT_NEAR(steps[i].time, a.steps[i].time, 1e-9) << "step " << i + 1;
    EXPECT_EQ(steps[i].forward, a.steps[i].forward) << "step " << i + 1;
    EXPECT_EQ(steps[i].lateral, a.steps[i].lateral) << "step " << i + 1;
    EXPECT_EQ(steps[i].tilt, a.steps[i].tilt) << "step " << i + 1;
  }
  EXPECT_EQ(e.summary.walk.relandings, a.relandings);
}

std::string walk_text() {
  return "name = \"w\"\n"
         "character = \"" + std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human3d.toml\"\n"
         "metric = \"md\"\n"
         "variations = 4\n"
         "m0 = \"w.m0.json\"\n"
         "[controller]\n"
         "skill = \"" + std::string(DIVERSE_SOURCE_DIR) + "/skills/walk3d.toml\"\n"
         "[constraints]\n"
         "weight = 5000.0\n"
         "fall_penalty = 50000.0\n"
         "[walk]\n"
         "steps = 30\n"
         "settle_steps = 10\n"
         "forward = { center = 1.0, half_width = 0.5 }\n";
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

// The error message of loading `text`, without the file name in front.
std::string error_of(const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / ("diverse_walk_task_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "w.toml").string();
  std::ofstream(path) << text;
  try {
    load_task(path);
  } catch (const UserError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(path, 0), 0u) << message;
    return message.substr(path.size());
  }
  return "(no error)";
}

TEST(WalkTaskFile, CommittedTasksParse) {
  const Task human = load_task(kTasks + "silly_walk.toml");
  EXPECT_TRUE(human.walk.enabled);
  EXPECT_EQ(human.walk.steps, 30);
  EXPECT_EQ(human.walk.settle_steps, 10);
  EXPECT_EQ(human.walk.forward_center, 1.0);
  EXPECT_EQ(human.walk.forward_half_width, 0.5);
  EXPECT_EQ(human.walk.lateral_half_width, 0.5);
  EXPECT_EQ(human.walk.max_tilt_deg, 15);
  EXPECT_EQ(human.constraints.fall_penalty, 50000);
  const Task robot = load_task(kTasks + "robot_silly_walk.toml");
  EXPECT_EQ(robot.walk.forward_center, 1.2);
  EXPECT_EQ(robot.walk.forward_half_width, 0.3);
  EXPECT_EQ(robot.walk.lateral_half_width, 0.3);
  EXPECT_EQ(load_task(kTasks + "jump_high.toml").walk.enabled, false);
}

TEST(WalkTaskFile, BadInputIsOneLine) {
  EXPECT_EQ(error_of(walk_text()), "(no error)");
  auto starts = [](const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; };
  EXPECT_PRED2(starts, error_of(replace(walk_text(), "steps = 30\n", "strides = 15\n")),
               ": walk.strides: expected no such key");
  EXPECT_EQ(error_of(replace(walk_text(), "settle_steps = 10", "settle_steps = 30")),
            ": walk.settle_steps: expected an integer in [0, 29], got 30");
  EXPECT_PRED2(starts, error_of(replace(walk_text(), "settle_steps = 10\n", "settle_steps = 10\nmax_flight = -0.1\n")),
               ": walk.max_flight: expected a number in [0, 10]");
  EXPECT_PRED2(starts, error_of(replace(walk_text(), "half_width = 0.5 }", "half = 0.5 }")),
               ": walk.forward.half: expected no such key");
  EXPECT_EQ(error_of(replace(walk_text(), "[walk]\nsteps = 30\nsettle_steps = 10\nforward = { center = 1.0, half_width = 0.5 }\n", "")),
            ": walk: expected a [walk] table for the walk controller \"skill\" (missing)");
  const std::string jump = replace(replace(walk_text(), "human3d.toml", "human2d.toml"), "walk3d", "jump2d");
  EXPECT_EQ(error_of(jump), ": walk: expected no [walk] table: the controller \"skill\" does not walk");
}

// The constraint penalty on made-up walks.
TEST(WalkConstraints, RangesFallsAndTurns) {
  const Task task = load_task(kTasks + "silly_walk.toml");
  const double K = task.constraints.weight;
  auto walk_of = [](int n, double forward, double lateral, double tilt_deg, double turn) {
    MotionSummary s;
    for (int i = 0; i < n; ++i) {
      WalkStep step;
      step.leg = i % 2;
      step.forward = forward;
      step.lateral = (i % 2 ? -1 : 1) * lateral;
      step.tilt = tilt_deg * M_PI / 180;
      step.heading = i >= 10 ? turn * (i - 9) / 20.0 : 0;
      s.walk.steps.push_back(step);
    }
    return s;
  };
  EXPECT_EQ(evaluate_constraints(task, walk_of(30, 1.0, 0.2, 5, 0)).total, 0);
  // The margin is the smallest slack of any term: the tilt's 10 degrees, or the foot-slip
  // bound's share left unused, counted as 0.1 m for all of it (task/term_foot_slip.h).
  MotionSummary planted = walk_of(30, 1.0, 0.2, 5, 0);
  planted.foot_slip = 0.0;  // 0.1 of slack
  EXPECT_NEAR(constraint_margin(task, planted), 0.1, 1e-12);
  planted.foot_slip = 0.015;  // half the 3 cm bound: 0.05
  EXPECT_NEAR(constraint_margin(task, planted), 0.05, 1e-12);
  MotionSummary tilted = walk_of(30, 1.0, 0.2, 12, 0);  // 3 degrees of tilt left
  EXPECT_NEAR(constraint_margin(task, tilted), 3 * M_PI / 180, 1e-12);
  // Every evaluated step 0.2 m short: 20 steps of K 0.2^2; the settling steps do not count.
  MotionSummary short_steps = walk_of(30, 0.3, 0.2, 5, 0);
  for (int i = 0; i < 10; ++i) short_steps.walk.steps[static_cast<size_t>(i)].forward = -3;
  EXPECT_NEAR(evaluate_constraints(task, short_steps).total, K * 20 * 0.04, 1e-6);
  EXPECT_NEAR(constraint_margin(task, short_steps), -0.2, 1e-12);
  EXPECT_NEAR(evaluate_constraints(task, walk_of(30, 1.0, 0.7, 5, 0)).total, K * 20 * 0.04, 1e-6);
  // Leaning 20 degrees: 5 degrees over on each evaluated step.
  const double over = 5 * M_PI / 180;
  EXPECT_NEAR(evaluate_constraints(task, walk_of(30, 1.0, 0.2, 20, 0)).total, K * 20 * over * over, 1e-6);
  // Turning 40 degrees over the evaluated steps: 10 over.
  const double turn = 10 * M_PI / 180;
  EXPECT_NEAR(evaluate_constraints(task, walk_of(30, 1.0, 0.2, 5, 40 * M_PI / 180)).total, K * turn * turn, 1e-6);
  // Turning round 90 degrees while settling, then walking straight: 60 over, although the
  // evaluated steps do not turn.
  MotionSummary round = walk_of(30, 1.0, 0.2, 5, 0);
  for (size_t i = 0; i < round.walk.steps.size(); ++i) round.walk.steps[i].heading = i >= 5 ? M_PI / 2 : 0;
  const double round_over = 60 * M_PI / 180;
  EXPECT_NEAR(evaluate_constraints(task, round).total, K * round_over * round_over, 1e-6);
  // Falls: 50,000 in the first step, linearly to 0 after the 30th.
  for (const int taken : {0, 15, 29}) {
    MotionSummary s = walk_of(taken, 1.0, 0.2, 5, 0);
    s.fell = true;
    const ConstraintReport r = evaluate_constraints(task, s);
    EXPECT_TRUE(r.fell);
    EXPECT_NEAR(r.total, 50000.0 * (1 - taken / 30.0), 1e-6) << taken;
    EXPECT_EQ(constraint_margin(task, s), -1);
  }
  MotionSummary blew_up;
  blew_up.unstable = true;
  EXPECT_EQ(evaluate_constraints(task, blew_up).total, 150000);
}

// The committed input walks. (The human's hand-authored start, silly_walk_start.json, hops
// in its third step: both feet off the ground for longer than max_flight.)
void expect_meets(const std::string& name) {
  const TaskEvaluator ev(load_task(kTasks + name + ".toml"));
  const ParameterSet p = ev.load_parameters(ev.task().m0);
  const Evaluation e = evaluate_once(ev, p);
  ASSERT_FALSE(e.failed) << e.failure;
  EXPECT_FALSE(e.fell) << e.summary.fall_reason;
  EXPECT_EQ(e.constraint, 0);
  const auto& steps = e.summary.walk.steps;
  ASSERT_EQ(steps.size(), 30u);
  for (size_t i = 0; i < steps.size(); ++i) EXPECT_EQ(steps[i].leg, static_cast<int>(i % 2)) << i;
  // The rollout stops at the last touch-down.
  EXPECT_NEAR(e.stats.time, steps.back().time, 1e-9);
  EXPECT_GT(constraint_margin(ev.task(), e.summary), 0);
  // 10 evaluated strides, 4 states, 10 samples each, in state order.
  ASSERT_EQ(e.poses.size(), 400u);
  for (size_t k = 0; k < e.poses.size(); ++k) {
    EXPECT_EQ(e.poses[k].phase, static_cast<int>((k / 10) % 4)) << k;
    EXPECT_NEAR(e.poses[k].phase_time, (k % 10 + 0.5) / 10, 1e-12);
    if (k > 0) {
      EXPECT_GT(e.poses[k].time, e.poses[k - 1].time);
    }
  }
  EXPECT_GE(e.poses.front().time, steps[9].time);
  EXPECT_LE(e.poses.back().time, steps.back().time);
  // The same parameters give the same walk on another worker.
  const auto other = ev.make_worker();
  const Evaluation again = ev.evaluate(p.values(), *other);
  EXPECT_EQ(again.stats.steps, e.stats.steps);
  EXPECT_EQ(again.poses.back().link_com, e.poses.back().link_com);
  // The independent audit counts the same steps and finds no broken rule.
  const WalkAudit a = audit_once(ev, p);
  expect_same_steps(e, a);
  EXPECT_TRUE(a.violations.empty()) << a.violations.front();
}

TEST(WalkEvaluation, HumanInputWalkMeetsTheTask) { expect_meets("silly_walk"); }
TEST(WalkEvaluation, RobotInputWalkMeetsTheTask) { expect_meets("robot_silly_walk"); }

// The recorded walks of tests/task/data were found at 2 ms, before the walk tasks ran at a
// coarser step: the tests that need their recorded behaviour simulate them at 2 ms.
Task task_at_2ms(const std::string& file) {
  Task task = load_task(kTasks + file);
  task.simulation.timestep = 0.002;
  return task;
}

// A walk's pose samples are in its stride's heading frame, so the metrics see its gait,
// not the direction it walks in. The bird robot of tests/task/data/robot_walk_turns_round.json
// turns about 140 degrees right during its settling steps and then walks straight: in
// world axes its root faces far from the start direction in every evaluated stride, in
// the poses it faces ahead, give or take its sway within a stride.
TEST(WalkEvaluation, PosesAreInTheStridesHeadingFrame) {
  Task task = task_at_2ms("robot_silly_walk.toml");
  task.walk.max_flight = 10;  // it hops at its start (WalkEvaluation.AHopIsAFall)
  const TaskEvaluator ev(task);
  const ParameterSet p = test_walk(ev, "robot_walk_turns_round.json");
  const Evaluation e = evaluate_once(ev, p);
  ASSERT_FALSE(e.fell) << e.summary.fall_reason;
  const auto& steps = e.summary.walk.steps;
  ASSERT_EQ(steps.size(), 30u);
  EXPECT_LT(steps[9].heading, -100 * M_PI / 180);  // turned round while settling
  // It breaks the task's turn rule (30 degrees from the start, at every touch-down).
  EXPECT_GT(e.report.total, 0);
  ASSERT_EQ(e.poses.size(), 400u);
  // The yaw of the root's standing forward axis, in world axes and in the pose samples.
  auto yaw = [](const Eigen::Quaterniond& root, const Eigen::Quaterniond& standing) {
    const Eigen::Vector3d forward = root * (standing.inverse() * Eigen::Vector3d::UnitX());
    return std::atan2(forward.y(), forward.x());
  };
  const Eigen::Quaterniond standing = root_orientation(ev.body(), ev.model().get()->qpos0);
  double worst = 0;
  for (const PoseSample& s : e.poses) worst = std::max(worst, std::fabs(yaw(s.root, standing)));
  EXPECT_LT(worst, 30 * M_PI / 180);
}

// Both feet off the ground for longer than max_flight is a hop, not a walk: the same
// robot pushes off into a hop while its swing foot is up in its first step.
TEST(WalkEvaluation, AHopIsAFall) {
  const TaskEvaluator ev(load_task(kTasks + "robot_silly_walk.toml"));
  ASSERT_EQ(ev.task().walk.max_flight, 0.05);
  const ParameterSet p = test_walk(ev, "robot_walk_turns_round.json");
  const Evaluation e = evaluate_once(ev, p);
  ASSERT_TRUE(e.fell);
  EXPECT_EQ(e.summary.fall_reason, "both feet were off the ground for longer than max_flight (a hop, not a walk)");
  EXPECT_LT(e.summary.walk.steps.size(), 2u);
  EXPECT_NEAR(e.report.terms.front().penalty, 50000.0 * (1 - e.summary.walk.steps.size() / 30.0), 1e-6);
}

// A step is measured from where the other foot is at the touch-down. A human walk that a
// run found under an earlier rule (from where the other foot had landed) moves its feet
// after they land: measured from the landing spots its steps met the 0.5 m minimum (C = 0).
// Between the feet at each touch-down, found from the feet's contacts, most of its steps
// go backward, and it breaks the task.
TEST(WalkEvaluation, AStepIsMeasuredFromWhereTheOtherFootIsNow) {
  Task task = task_at_2ms("silly_walk.toml");
  task.walk.from_footprint = false;  // the rule this test is about (the task's is footprints)
  const TaskEvaluator ev(task);
  const ParameterSet p = test_walk(ev, "human_walk_slides_back.json");
  const Evaluation e = evaluate_once(ev, p);
  ASSERT_FALSE(e.fell) << e.summary.fall_reason;
  const auto& steps = e.summary.walk.steps;
  ASSERT_EQ(steps.size(), 30u);
  const double shortest = ev.task().walk.forward_center - ev.task().walk.forward_half_width;
  int backward = 0;
  for (std::size_t i = 10; i < steps.size(); ++i) {
    EXPECT_LT(steps[i].forward, shortest) << "step " << i + 1;
    backward += steps[i].forward < 0 ? 1 : 0;
  }
  EXPECT_GT(backward, 10);
  double step_forward = 0;
  for (const auto& term : e.report.terms)
    if (term.name == "step_forward") step_forward = term.penalty;
  EXPECT_GT(step_forward, 0);
  EXPECT_GT(e.report.total, 0);
  // The independent audit of the same walk counts the same steps and fails it too.
  const WalkAudit a = audit_once(ev, p);
  expect_same_steps(e, a);
  EXPECT_FALSE(a.violations.empty());
}

// step_from = "footprint": a step from where the other foot last touched down. The
// committed input walks' steps are then the audit's footprint-to-footprint steps, longer
// than from where the other foot is (it rolls and slides forward while down), and still
// within their tasks' ranges. The human walk that slides its feet back after landing
// (above) breaks the footprint rule too, its touch-downs found from the contacts, and a
// foot-slip bound ([constraints] foot_slip) adds what it slides: decimetres a stance.
TEST(WalkEvaluation, FromFootprintsTheStepsAreTheAuditsAndASlidingFootBreaksTheSlipBound) {
  for (const std::string name : {"silly_walk", "robot_silly_walk"}) {
    Task task = load_task(kTasks + name + ".toml");
    ASSERT_TRUE(task.walk.from_footprint) << name;
    task.walk.from_footprint = false;
    const Evaluation from_foot = evaluate_once(TaskEvaluator(task), TaskEvaluator(task).load_parameters(task.m0));
    task.walk.from_footprint = true;
    const TaskEvaluator ev(task);
    const ParameterSet p = ev.load_parameters(ev.task().m0);
    const Evaluation e = evaluate_once(ev, p);
    ASSERT_FALSE(e.fell) << name << ": " << e.summary.fall_reason;
    EXPECT_EQ(e.constraint, 0) << name;
    const WalkAudit a = audit_once(ev, p);
    const auto& steps = e.summary.walk.steps;
    ASSERT_EQ(a.steps.size(), steps.size());
    for (size_t k = 0; k < steps.size(); ++k) {
      EXPECT_NEAR(steps[k].forward, a.steps[k].footprint_forward, 0.01) << name << " step " << k + 1;
      EXPECT_NEAR(steps[k].lateral, a.steps[k].footprint_lateral, 0.01) << name << " step " << k + 1;
    }
    ASSERT_EQ(from_foot.summary.walk.steps.size(), steps.size());
    for (size_t k = 10; k < steps.size(); ++k)
      EXPECT_GT(steps[k].forward, from_foot.summary.walk.steps[k].forward + 0.03) << name << " step " << k + 1;
  }
  Task task = task_at_2ms("silly_walk.toml");
  task.walk.from_footprint = true;
  const TaskEvaluator loose(task);
  const ParameterSet p = test_walk(loose, "human_walk_slides_back.json");
  const Evaluation e = evaluate_once(loose, p);
  ASSERT_FALSE(e.fell) << e.summary.fall_reason;
  // Its touch-downs, found from the contacts, are still steps backward.
  EXPECT_GT(e.constraint, 0);
  auto slip = std::make_shared<FootSlipConstraint>("constraints.foot_slip");
  slip->per_stance = 0.02;
  task.constraints.terms.push_back(slip);
  const TaskEvaluator bounded(task);
  const Evaluation f = evaluate_once(bounded, p);
  EXPECT_GT(f.summary.foot_slip, 0.1);
  double slip_penalty = -1;
  for (const auto& term : f.report.terms)
    if (term.name == "foot_slip") slip_penalty = term.penalty;
  EXPECT_NEAR(slip_penalty, 5000 * std::pow(f.summary.foot_slip - 0.02, 2), 1e-9);
  EXPECT_GT(f.constraint, 0);
}

// Steps are found from the feet's contacts, as the audit finds them. A robot walk that a
// run found while steps were taken from the controller's strike states shuffles: now and
// then it sets its swing foot down beside or behind the other one while its lift state
// still runs, lifts it again and lands it 1.5 m ahead when its strike state ends. Counted
// at the strikes, its 30 steps were all 1.47 to 1.49 m (C = 0); the audit found steps of
// -0.26 m and 15 re-landings. The task now counts the steps the audit counts, and fails it.
TEST(WalkEvaluation, ASwingFootSetDownMidSwingIsAStep) {
  const TaskEvaluator ev(task_at_2ms("robot_silly_walk.toml"));
  const ParameterSet p = test_walk(ev, "robot_walk_sets_foot_down_midswing.json");
  const Evaluation e = evaluate_once(ev, p);
  ASSERT_FALSE(e.fell) << e.summary.fall_reason;
  const auto& steps = e.summary.walk.steps;
  ASSERT_EQ(steps.size(), 30u);
  for (size_t i = 1; i < steps.size(); ++i) EXPECT_NE(steps[i].leg, steps[i - 1].leg) << i;
  double shortest = INFINITY;
  for (size_t i = 10; i < steps.size(); ++i) shortest = std::min(shortest, steps[i].forward);
  EXPECT_LT(shortest, 0.0);
  EXPECT_GT(e.summary.walk.relandings, 0);
  EXPECT_GT(e.report.total, 0);
  const WalkAudit a = audit_once(ev, p);
  expect_same_steps(e, a);
  EXPECT_FALSE(a.violations.empty());
}

TEST(WalkEvaluation, FallEndsTheRollout) {
  const TaskEvaluator ev(load_task(kTasks + "silly_walk.toml"));
  ParameterSet p = ev.load_parameters(ev.task().seed.base);
  // Torso bent forward to its limit, no balance feedback: it falls within a few steps.
  p.set("lift.torso.waist", p.specs()[static_cast<size_t>(p.find("lift.torso.waist"))].lower);
  p.set("strike.torso.waist", p.specs()[static_cast<size_t>(p.find("strike.torso.waist"))].lower);
  const Evaluation e = evaluate_once(ev, p);
  ASSERT_TRUE(e.fell);
  EXPECT_LT(e.summary.walk.steps.size(), 30u);
  EXPECT_NEAR(e.stats.time, e.summary.end_time, 1e-9);
  EXPECT_LT(e.stats.time, 20.0);
  ASSERT_EQ(e.report.terms.front().name, "fall");
  EXPECT_NEAR(e.report.terms.front().penalty, 50000.0 * (1 - e.summary.walk.steps.size() / 30.0), 1e-6);
  EXPECT_TRUE(e.poses.empty());
}

}  // namespace
}  // namespace diverse

namespace diverse {
namespace {

// Walks are judged at half their timestep too: the committed input walks meet their
// tasks at half the step (the check adds a "half_timestep" term of 0 and counts the
// check's steps, about twice the walk's), and a walk whose step breaks the rules at half
// the step does not meet the task. Steps past a rule broken in the evaluated window are
// counted as decided.
TEST(WalkHalfTimestep, InputWalksHoldAtHalfTheStep) {
  for (const char* name : {"silly_walk.toml", "robot_silly_walk.toml"}) {
    SCOPED_TRACE(name);
    Task task = load_task(kTasks + name);
    task.constraints.half_timestep = true;
    const TaskEvaluator ev(task);
    const ParameterSet m0 = ev.load_parameters(task.m0);
    EvaluationOptions checked;
    checked.samples_per_phase = 0;
    checked.half_timestep_check = true;
    const Evaluation e = ev.evaluate(m0.values(), *ev.make_worker(), checked);
    EXPECT_EQ(e.constraint, 0.0);
    EXPECT_EQ(e.decided_step, -1);
    const auto term = std::find_if(e.report.terms.begin(), e.report.terms.end(),
                                   [](const ConstraintTerm& t) { return t.name == "half_timestep"; });
    ASSERT_NE(term, e.report.terms.end());
    EXPECT_EQ(term->penalty, 0.0);
    EXPECT_GT(e.check_steps, 1.8 * e.stats.steps);
    EXPECT_LT(e.check_steps, 2.2 * e.stats.steps);

    // Narrow the forward range to exclude the input walk's steps: it no longer meets the
    // task, the outcome is decided at the first evaluated step, and no check runs.
    task.walk.forward_half_width = 0.01;
    task.walk.forward_center = 3.0;
    const TaskEvaluator narrow(task);
    const Evaluation n = narrow.evaluate(m0.values(), *narrow.make_worker(), checked);
    EXPECT_GT(n.constraint, 0.0);
    EXPECT_EQ(n.check_steps, 0);
    ASSERT_GE(n.decided_step, 0);
    EXPECT_GT(n.steps_after_decided, 0);
    EXPECT_NEAR(n.decided_step * narrow.model().get()->opt.timestep,
                n.summary.walk.steps[static_cast<size_t>(task.walk.settle_steps)].time, 0.01);

    // Ended there (the optimizer's rollouts): the walk stops at that step, and its one
    // evaluated step stands for all of them. These walks repeat their strides, so the
    // extrapolated C is within 25 % of the whole walk's, from about a third of the steps:
    // the human's 0.1 %, the robot's 23 % (its left and right steps differ; 10 % with steps
    // measured from the other foot where it is rather than from its footprint).
    EvaluationOptions ended = checked;
    ended.end_when_decided = true;
    const Evaluation x = narrow.evaluate(m0.values(), *narrow.make_worker(), ended);
    EXPECT_TRUE(x.summary.ended_decided);
    EXPECT_FALSE(x.fell);
    EXPECT_EQ(x.summary.walk.steps.size(), static_cast<size_t>(task.walk.settle_steps) + 1);
    EXPECT_LT(x.stats.steps, n.stats.steps / 2);
    std::printf("%s: C %.0f walked to the end, %.0f ended at its first evaluated step\n", name, n.constraint,
                x.constraint);
    EXPECT_NEAR(x.constraint, n.constraint, 0.25 * n.constraint);
    const auto extra = std::find_if(x.report.terms.begin(), x.report.terms.end(),
                                    [](const ConstraintTerm& t) { return t.name == "ended_decided"; });
    ASSERT_NE(extra, x.report.terms.end());
    EXPECT_EQ(extra->violation, task.walk.steps - task.walk.settle_steps);
    // The input walk itself is never ended.
    const Evaluation m = ev.evaluate(m0.values(), *ev.make_worker(), ended);
    EXPECT_EQ(m.constraint, 0.0);
    EXPECT_EQ(m.stats.steps, e.stats.steps);
  }
}

}  // namespace
}  // namespace diverse
