// The robustness suite (robust/robustness.h) and the perturbations it adds to a rollout
// (EvaluationOptions::push and friction_scale, task/evaluate.h), on real rollouts of the
// 3D backwards jump's input motion (it keeps most of its neighbourhood): a small push in
// a ground phase still lands in the disc, a huge one does not; a push that is never
// reached changes nothing, and a plain rollout replays bit for bit in plain MuJoCo; the
// friction changes the motion and is back on the worker after the rollout; the suite's
// JSON is the same on 1 and 2 threads, with its pushes inside their ground phases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "core/thread_pool.h"
#include "eval/motion_problem.h"
#include "robust/robustness.h"
#include "task/evaluate.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

struct Fixture {
  TaskEvaluator ev;
  ParameterSet m0;
  explicit Fixture(const std::string& name) : ev(load_task(kTasks + name + ".toml")), m0(ev.load_parameters(ev.task().m0)) {}
};

EvaluationOptions plain() {
  EvaluationOptions o;
  o.samples_per_phase = 0;
  return o;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(Push, SmallPushStillLandsHugePushDoesNot) {
  const Fixture f("jump_backwards");
  auto worker = f.ev.make_worker();
  const Evaluation base = f.ev.evaluate(f.m0.values(), *worker, plain());
  ASSERT_EQ(base.constraint, 0.0);
  ASSERT_GT(base.phases.takeoff(), 0.2);
  EXPECT_EQ(base.push_time, -1);

  // Forward, halfway to take-off: 0.2 m/s is absorbed, 3 m/s is not.
  EvaluationOptions small = plain();
  small.push.time = 0.5 * base.phases.takeoff();
  small.push.dv = {0.2, 0, 0};
  const Evaluation pushed = f.ev.evaluate(f.m0.values(), *worker, small);
  EXPECT_GE(pushed.push_time, small.push.time);
  EXPECT_LT(pushed.push_time, small.push.time + 2 * worker->model()->opt.timestep);
  EXPECT_EQ(pushed.constraint, 0.0) << pushed.summary.fall_reason;
  EXPECT_FALSE(pushed.fell);
  // It still landed in the disc of radius 0.25 m around x = -0.8, but not where M0 did.
  EXPECT_LT(std::hypot(pushed.summary.feet_x + 0.8, pushed.summary.feet_y), 0.25);
  EXPECT_NE(pushed.summary.feet_x, base.summary.feet_x);

  EvaluationOptions huge = small;
  huge.push.dv = {3.0, 0, 0};
  const Evaluation thrown = f.ev.evaluate(f.m0.values(), *worker, huge);
  EXPECT_GE(thrown.push_time, 0);
  EXPECT_GT(thrown.constraint, 0.0);

  // The same after touch-down, sideways: 0.1 m/s 0.3 s after it is absorbed (in the first
  // 0.2 s even 0.05 m/s topples this landing within the next second).
  EvaluationOptions late = plain();
  late.push.time = base.phases.landing() + 0.3;
  late.push.dv = {0, 0.1, 0};
  EXPECT_EQ(f.ev.evaluate(f.m0.values(), *worker, late).constraint, 0.0);
  late.push.dv = {0, 3.0, 0};
  EXPECT_GT(f.ev.evaluate(f.m0.values(), *worker, late).constraint, 0.0);
}

// Without a push (the default, as the optimizer runs) nothing changes: a rollout with a
// push past its end is the plain one bit for bit, and the plain rollout's record replays
// exactly with plain mj_step, so nothing touched its velocities.
TEST(Push, NeverAppliedUnlessAsked) {
  const EvaluationOptions defaults;
  EXPECT_LT(defaults.push.time, 0);
  EXPECT_EQ(defaults.friction_scale, 1.0);
  const Fixture f("jump_backwards");
  auto worker = f.ev.make_worker();
  StepRecorder record;
  EvaluationOptions recorded = plain();
  recorded.recorder = &record;
  const Evaluation a = f.ev.evaluate(f.m0.values(), *worker, recorded);
  EXPECT_EQ(a.push_time, -1);
  EvaluationOptions never = plain();
  never.push.time = 1e6;
  never.push.dv = {5, 5, 5};
  const Evaluation b = f.ev.evaluate(f.m0.values(), *worker, never);
  EXPECT_EQ(b.push_time, -1);
  EXPECT_TRUE(same_bits(a.constraint, b.constraint));
  EXPECT_EQ(a.stats.steps, b.stats.steps);
  EXPECT_TRUE(same_bits(a.stats.effort, b.stats.effort));
  EXPECT_TRUE(same_bits(a.summary.feet_x, b.summary.feet_x));
  EXPECT_TRUE(same_bits(a.summary.feet_y, b.summary.feet_y));
  mjModel* m = mj_copyModel(nullptr, f.ev.model().get());
  EXPECT_EQ(replay(m, record), 0.0);
  mj_deleteModel(m);
  // A push of 0 m/s is applied (the velocity-dependent terms computed again) and changes
  // nothing either.
  EvaluationOptions zero = plain();
  zero.push.time = 0.5 * a.phases.takeoff();
  const Evaluation c = f.ev.evaluate(f.m0.values(), *worker, zero);
  EXPECT_GE(c.push_time, zero.push.time);
  EXPECT_TRUE(same_bits(a.constraint, c.constraint));
  EXPECT_EQ(a.stats.steps, c.stats.steps);
  EXPECT_TRUE(same_bits(a.stats.effort, c.stats.effort));
  EXPECT_TRUE(same_bits(a.summary.feet_x, c.summary.feet_x));
  // A pushed rollout cannot be recorded: its record would not replay.
  EvaluationOptions both = never;
  both.recorder = &record;
  EXPECT_THROW(f.ev.evaluate(f.m0.values(), *worker, both), std::logic_error);
  // Nor does the optimizer's problem take a push or a friction scale.
  const MotionProblem problem(f.ev, parse_distance("md"), f.m0.normalized(), 1);
  EXPECT_THROW(problem.simulate(f.m0.normalized(), never), std::logic_error);
  EvaluationOptions icy = plain();
  icy.friction_scale = 0.5;
  EXPECT_THROW(problem.simulate(f.m0.normalized(), icy), std::logic_error);
  EXPECT_EQ(problem.simulate(f.m0.normalized(), plain()).constraint, a.constraint);
}

TEST(Friction, ChangesTheMotionAndIsRestoredAfter) {
  const Fixture f("jump_backwards");
  auto worker = f.ev.make_worker();
  const mjModel* shared = f.ev.model().get();
  const Evaluation base = f.ev.evaluate(f.m0.values(), *worker, plain());
  ASSERT_EQ(base.constraint, 0.0);
  EvaluationOptions slippery = plain();
  slippery.friction_scale = 0.05;  // ice: the push-off slips
  const Evaluation ice = f.ev.evaluate(f.m0.values(), *worker, slippery);
  EXPECT_GT(ice.constraint, 0.0);
  for (int k = 0; k < 3 * shared->ngeom; ++k)
    ASSERT_TRUE(same_bits(worker->model()->geom_friction[k], shared->geom_friction[k])) << k;
  EvaluationOptions rough = plain();
  rough.friction_scale = 1.5;
  const Evaluation grip = f.ev.evaluate(f.m0.values(), *worker, rough);
  EXPECT_NE(grip.summary.feet_x, base.summary.feet_x);
  for (int k = 0; k < 3 * shared->ngeom; ++k)
    ASSERT_TRUE(same_bits(worker->model()->geom_friction[k], shared->geom_friction[k])) << k;
  // And the worker's next plain rollout is the plain one.
  const Evaluation again = f.ev.evaluate(f.m0.values(), *worker, plain());
  EXPECT_TRUE(same_bits(again.summary.feet_x, base.summary.feet_x));
  EXPECT_EQ(again.stats.steps, base.stats.steps);
  // SimWorker::reset restores the friction by itself as well.
  worker->model()->geom_friction[0] = 0.123;
  worker->reset();
  EXPECT_TRUE(same_bits(worker->model()->geom_friction[0], shared->geom_friction[0]));
}

TEST(Suite, SameOnOneAndTwoThreadsWithPushesInTheirGroundPhases) {
  const Fixture f("jump_backwards");
  RobustnessSuite suite;
  suite.parameter_samples = 2;
  suite.push_samples = 8;
  suite.friction_factors = {0.6};
  const std::vector<MotionUnderTest> motions{{"M0", 0, f.m0}};
  ThreadPool one(1), two(2);
  const auto results = run_robustness_suite(f.ev, motions, suite, one);
  const nlohmann::json a = robustness_json(f.ev, suite, results);
  const nlohmann::json b = robustness_json(f.ev, motions, suite, two);
  EXPECT_EQ(a.dump(), b.dump());

  ASSERT_EQ(results.size(), 1u);
  const MotionRobustness& r = results[0];
  EXPECT_EQ(r.constraint, 0.0);
  EXPECT_EQ(r.count(), 2 + 8 + 1 + 1);
  EXPECT_EQ(r.count(PerturbationKind::kPush), 8);
  const Evaluation base = f.ev.evaluate_named(f.m0, plain());
  int before = 0, after = 0;
  for (const PerturbedRollout& p : r.rollouts) {
    if (p.kind != PerturbationKind::kPush) continue;
    EXPECT_GE(p.push_time, 0);
    EXPECT_NEAR(std::hypot(p.dv[0], p.dv[1]), suite.push_speed, 1e-12);
    if (p.phase == "takeoff") {
      ++before;
      EXPECT_LT(p.push_time, base.phases.takeoff());
    } else {
      ASSERT_EQ(p.phase, "landing");
      ++after;
      EXPECT_GE(p.push_time, base.phases.landing());
      EXPECT_LE(p.push_time, base.phases.landing() + f.ev.task().simulation.settle_time + 0.01);
    }
  }
  EXPECT_EQ(before, 4);
  EXPECT_EQ(after, 4);
  // Four directions for the 3D root, each in both phases.
  EXPECT_EQ(a["suite"]["push_directions"].size(), 4u);
  const std::string shares = robustness_shares(a["motions"][0], "test");
  EXPECT_NE(shares.find("params "), std::string::npos) << shares;
  EXPECT_NE(shares.find("/12 = "), std::string::npos) << shares;
  // Another seed draws other perturbations.
  suite.seed = 2;
  const nlohmann::json c = robustness_json(f.ev, motions, suite, two);
  EXPECT_NE(a["motions"][0]["kinds"]["parameters"].dump(), c["motions"][0]["kinds"]["parameters"].dump());
}

// robustness.json lets a user see a failure again: each parameter draw's parameters,
// simulated again, give its C bit for bit, and a fall after landing says when it came.
// jump_high's input motion: most of its perturbations fall after touch-down.
TEST(Suite, RecordsEachDrawsParametersAndWhenAFallCame) {
  const Fixture f("jump_high");
  RobustnessSuite suite;
  suite.parameter_samples = 6;
  suite.push_samples = 4;
  suite.friction_factors = {};
  const std::vector<MotionUnderTest> motions{{"M0", 0, f.m0}};
  ThreadPool pool(2);
  const nlohmann::json j = robustness_json(f.ev, motions, suite, pool);
  EvaluationOptions judged = plain();
  judged.half_timestep_check = true;
  int falls_after_landing = 0;
  for (const nlohmann::json& r : j["motions"][0]["kinds"]["parameters"]["rollouts"]) {
    ParameterSet drawn = f.m0;
    drawn.set_from_json(r["parameters"], "robustness.json");
    const Evaluation e = f.ev.evaluate_named(drawn, judged);
    EXPECT_TRUE(same_bits(e.constraint, r["constraint"].get<double>())) << r.dump();
    EXPECT_EQ(e.fell, r.contains("fell"));
  }
  for (const char* kind : {"parameters", "pushes"}) {
    for (const nlohmann::json& r : j["motions"][0]["kinds"][kind]["rollouts"]) {
      if (!r.contains("fell_after_touchdown")) continue;
      ++falls_after_landing;
      EXPECT_TRUE(r.contains("fell")) << r.dump();
      EXPECT_GE(r["fell_after_touchdown"].get<double>(), 0.0);
      EXPECT_LE(r["fell_after_touchdown"].get<double>(), f.ev.task().simulation.settle_max + 1e-9);
    }
    for (const nlohmann::json& r : j["motions"][0]["kinds"][kind]["rollouts"]) {
      if (r["holds"].get<bool>()) {
        EXPECT_FALSE(r.contains("fell_after_touchdown")) << r.dump();
      }
    }
  }
  EXPECT_GT(falls_after_landing, 0);
  EXPECT_FALSE(j["motions"][0]["kinds"]["pushes"]["rollouts"][0].contains("parameters"));
}

// The planar human is pushed forward and backward only, in its plane.
TEST(Suite, PlanarCharactersArePushedInTheirPlane) {
  const Fixture f("jump_high");
  RobustnessSuite suite;
  suite.parameter_samples = 1;
  suite.push_samples = 4;
  suite.friction_factors = {};
  suite.half_timestep = false;
  ThreadPool pool(2);
  const auto r = run_robustness_suite(f.ev, {{"M0", 0, f.m0}}, suite, pool);
  ASSERT_EQ(r[0].count(PerturbationKind::kPush), 4);
  for (const PerturbedRollout& p : r[0].rollouts) {
    if (p.kind != PerturbationKind::kPush) continue;
    EXPECT_TRUE(p.direction == "forward" || p.direction == "backward") << p.direction;
    EXPECT_EQ(p.dv[1], 0.0);
  }
}

TEST(Suite, MirrorKeepsNormalizedCoordinatesInTheBox) {
  EXPECT_EQ(mirror_unit(0.3), 0.3);
  EXPECT_DOUBLE_EQ(mirror_unit(-0.1), 0.1);
  EXPECT_DOUBLE_EQ(mirror_unit(1.1), 0.9);
  EXPECT_DOUBLE_EQ(mirror_unit(2.25), 0.25);
  EXPECT_EQ(mirror_unit(1.0), 1.0);
  EXPECT_EQ(mirror_unit(0.0), 0.0);
}

}  // namespace
}  // namespace diverse
