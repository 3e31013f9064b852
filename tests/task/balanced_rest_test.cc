// At rest means balanced: a jump's landing counts as at rest only when the COM is slow and
// its capture point lies over the feet's contacts, both for the last rest_hold seconds
// (task/support.h, TaskSimulation::balanced_rest). Before, a landing slower than 0.25 m/s
// one second after touch-down was at rest, and a third of the high jump's perturbations
// that met the task that way toppled over in the next two seconds.
#include <gtest/gtest.h>

#include <mujoco/mujoco.h>

#include <cmath>
#include <random>
#include <string>

#include "physics/rollout.h"
#include "task/evaluate.h"
#include "task/support.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";
const std::string kTopples = std::string(DIVERSE_SOURCE_DIR) + "/tests/task/data/backflip_topples.json";

EvaluationOptions plain() {
  EvaluationOptions o;
  o.samples_per_phase = 0;
  return o;
}

// The same task, judged 2 s later: at rest no sooner than 3 s after touch-down.
Task two_seconds_longer(Task task) {
  task.simulation.settle_time += 2.0;
  task.simulation.settle_max += 2.0;
  task.simulation.max_time += 2.0;
  return task;
}


// A backflip that slows below settle_speed one second after touch-down but rocks on its
// heels with its capture point behind them: without balanced_rest it met the task and
// then fell backwards; with it, the rollout goes on and the landing never comes to rest.
// (Found at 1 ms with the joint drive's explicit way, the backflip task of that time:
// tests/task/data/backflip_explicit.toml.)
TEST(BalancedRest, ASlowToppleIsNotAtRest) {
  Task task = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tests/task/data/backflip_explicit.toml");
  ASSERT_TRUE(task.simulation.balanced_rest);
  Task unbalanced = task;
  unbalanced.simulation.balanced_rest = false;

  const TaskEvaluator ev_unbalanced(unbalanced);
  const ParameterSet p = ev_unbalanced.load_parameters(kTopples);
  auto w1 = ev_unbalanced.make_worker();
  const Evaluation slow = ev_unbalanced.evaluate(p.values(), *w1, plain());
  EXPECT_EQ(slow.constraint, 0) << "without the balance test this landing counted as at rest";
  EXPECT_TRUE(slow.summary.settled);

  const TaskEvaluator ev_longer(two_seconds_longer(unbalanced));
  auto w2 = ev_longer.make_worker();
  const Evaluation later = ev_longer.evaluate(p.values(), *w2, plain());
  EXPECT_TRUE(later.fell) << "it topples after the moment it was judged at rest";

  const TaskEvaluator ev(task);
  auto w3 = ev.make_worker();
  const Evaluation judged = ev.evaluate(p.values(), *w3, plain());
  EXPECT_TRUE(judged.fell);
  EXPECT_FALSE(judged.summary.settled);
  EXPECT_GE(judged.constraint, task.constraints.fall_penalty);
  EXPECT_GT(judged.summary.end_time, slow.summary.end_time);
}

// Every jump's input motion comes to rest balanced, and still stands two seconds later.
TEST(BalancedRest, EveryJumpInputMotionStandsTwoSecondsLonger) {
  for (const char* name : {"jump_high", "jump_forward", "jump_onto", "jump_backwards", "robot_jump", "backflip",
                           "jump_over"}) {
    const Task task = load_task(kTasks + name + ".toml");
    const TaskEvaluator ev(task);
    const ParameterSet p = ev.load_parameters(task.m0);
    auto w = ev.make_worker();
    const Evaluation e = ev.evaluate(p.values(), *w, plain());
    EXPECT_EQ(e.constraint, 0) << name;
    EXPECT_TRUE(e.summary.settled) << name;
    const TaskEvaluator longer(two_seconds_longer(task));
    auto wl = longer.make_worker();
    const Evaluation l = longer.evaluate(p.values(), *wl, plain());
    EXPECT_FALSE(l.fell) << name << ": " << l.summary.fall_reason;
    EXPECT_EQ(l.constraint, 0) << name;
  }
}

// Around the high jump's input motion (sigma 0.005, 48 draws), every perturbation that
// meets the task still stands two seconds after it was judged at rest. Without the balance
// test about a third of them fall in those two seconds.
TEST(BalancedRest, NeighboursThatMeetTheTaskDoNotToppleLater) {
  const Task task = load_task(kTasks + "jump_high.toml");
  const TaskEvaluator ev(task), longer(two_seconds_longer(task));
  auto w = ev.make_worker();
  auto wl = longer.make_worker();
  const Eigen::VectorXd x0 = ev.load_parameters(task.m0).normalized();
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0, 1);
  int met = 0;
  for (int k = 0; k < 48; ++k) {
    Eigen::VectorXd x = x0;
    for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = std::clamp(x[i] + 0.005 * g(rng), 0.0, 1.0);
    const Evaluation e = ev.evaluate_normalized(x, *w, plain());
    if (e.constraint > 0) continue;
    ++met;
    const Evaluation l = longer.evaluate_normalized(x, *wl, plain());
    EXPECT_FALSE(l.fell) << "draw " << k << ": " << l.summary.fall_reason;
  }
  EXPECT_GE(met, 8) << "the neighbourhood should hold some motions that meet the task";
}

// The capture point: over the feet of the high jump's input motion at rest, beyond the
// toes when the COM moves forward at 1.5 m/s, behind the heels at 1.5 m/s backwards; the
// same for the 3D human's backwards jump, and sideways too (at 1 m/s its input motion,
// which comes to rest in a stride, one foot ahead of the other, still has its capture
// point over its feet: 0.3 m ahead of the COM). No foot contact: -infinity.
TEST(BalancedRest, CapturePointMarginAtRest) {
  for (const char* name : {"jump_high", "jump_backwards"}) {
    const Task task = load_task(kTasks + name + ".toml");
    const TaskEvaluator ev(task);
    auto w = ev.make_worker();
    StepRecorder record;
    EvaluationOptions o = plain();
    o.recorder = &record;
    const Evaluation e = ev.evaluate(ev.load_parameters(task.m0).values(), *w, o);
    ASSERT_TRUE(e.summary.settled) << name;
    mjModel* m = mj_copyModel(nullptr, ev.model().get());
    mjData* d = mj_makeData(m);
    mju_copy(d->qpos, record.qpos.data() + (record.steps() - 1) * record.nq, record.nq);
    mj_forward(m, d);
    const int root = ev.body().root_body;
    const std::array<double, 3> com{d->subtree_com[3 * root], d->subtree_com[3 * root + 1],
                                    d->subtree_com[3 * root + 2]};
    const double still = capture_point_margin(m, d, ev.body(), com, {0, 0, 0});
    EXPECT_GT(still, 0.0) << name;
    EXPECT_LT(still, 0.2) << name << ": half a foot's length at most";
    EXPECT_LT(capture_point_margin(m, d, ev.body(), com, {1.5, 0, 0}), 0.0) << name;
    EXPECT_LT(capture_point_margin(m, d, ev.body(), com, {-1.5, 0, 0}), 0.0) << name;
    const double sideways = capture_point_margin(m, d, ev.body(), com, {0, 1, 0});
    if (ev.body().root == RootKind::kPlanar) {
      EXPECT_EQ(sideways, still) << name << ": the planar character cannot fall sideways";
    } else {
      EXPECT_LT(sideways, 0.0) << name;
    }
    d->ncon = 0;
    EXPECT_EQ(capture_point_margin(m, d, ev.body(), com, {0, 0, 0}), -INFINITY) << name;
    mj_deleteData(d);
    mj_deleteModel(m);
  }
}

// The task file's keys: balanced_rest on by default, rest_hold in [0, 5] s.
TEST(BalancedRest, TaskKeys) {
  const Task task = load_task(kTasks + "jump_high.toml");
  EXPECT_TRUE(task.simulation.balanced_rest);
  EXPECT_DOUBLE_EQ(task.simulation.rest_hold, 0.5);
}

}  // namespace
}  // namespace diverse
