// The skill engine (control/skill_controller.h) on a tiny planar biped
// (tests/control/tiny_biped.h): every transition kind moves the machine at the moment its
// event happens, the modules do what they say (J^T balance holds the COM over the feet;
// the landing hips, spotting and stance control are checked bit for bit against the
// controller they came from in skill_replay_test.cc), targets follow numbers, parameters,
// curves and per-side values, and the torques stay within the joint limits.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "control/skill_controller.h"
#include "physics/rollout.h"
#include "task/evaluate.h"
#include "tiny_biped.h"

namespace diverse {
namespace {

// A skill for the tiny biped: the target sets and gains every test shares, then `rest`
// (modules and phases): tests/control/tiny_biped.h.
std::string skill(const std::string& rest) { return tiny_biped::skill(rest); }

struct Rollout {
  Evaluation e;
  StepRecorder record;
};

Rollout run(const std::string& name, const std::string& rest, const std::vector<double>& values = {}) {
  const TaskEvaluator ev(tiny_biped::task(name, skill(rest)));
  Rollout r;
  EvaluationOptions o;
  o.samples_per_phase = 0;
  o.recorder = &r.record;
  auto w = ev.make_worker();
  r.e = ev.evaluate(values, *w, o);
  return r;
}

const double kDt = 0.002;

// The engine alone on the standing biped for `seconds`, with no task rules to end the
// rollout: per step (as the controller saw it), the phase after its transitions, the
// root pitch, the COM height and whether the left foot touches anything.
struct Trace {
  std::vector<int> phase;
  std::vector<double> time, pitch, com_z;
  std::vector<bool> foot_l;
};

class TraceHooks : public StepHooks {
 public:
  TraceHooks(const Character& body, Controller& controller, JointDrive& drive, int foot)
      : body_(body), controller_(controller), drive_(drive), foot_(foot) {}
  void control(mjModel* m, mjData* d) override {
    controller_.control(m, d, scan_contacts(m, d, body_), drive_);
  }
  bool observe(const mjModel* m, const mjData* d) override {
    bool touching = false;
    for (int i = 0; i < d->ncon; ++i) {
      const mjContact& c = d->contact[i];
      touching = touching || (c.exclude == 0 && (m->geom_bodyid[c.geom1] == foot_ || m->geom_bodyid[c.geom2] == foot_));
    }
    trace.phase.push_back(controller_.phase());
    trace.time.push_back(d->time);
    trace.pitch.push_back(d->qpos[body_.root_pitch_qpos]);
    trace.com_z.push_back(controller_.com()[2]);
    trace.foot_l.push_back(touching);
    return false;
  }
  Trace trace;

 private:
  const Character& body_;
  Controller& controller_;
  JointDrive& drive_;
  int foot_;
};

Trace simulate(const std::string& name, const std::string& rest, double seconds, const std::vector<double>& values = {}) {
  const TaskEvaluator ev(tiny_biped::task(name, skill(rest)));
  auto w = ev.make_worker();
  mjModel* m = w->model();
  mjData* d = w->data();
  mj_resetData(m, d);
  mj_forward(m, d);
  const Character& body = ev.body();
  auto controller = ev.task().controller_type->make(body, *ev.task().controller_config, values);
  controller->reset(m, d);
  JointDrive drive = make_drive(body);
  TraceHooks hooks(body, *controller, drive, mj_name2id(m, mjOBJ_BODY, "foot_l"));
  run_rollout(*w, hooks, static_cast<int>(seconds / m->opt.timestep), drive, nullptr);
  return hooks.trace;
}

// The first step in `phase`, or -1.
int first_step(const Trace& t, int phase) {
  for (size_t i = 0; i < t.phase.size(); ++i)
    if (t.phase[i] == phase) return static_cast<int>(i);
  return -1;
}

TEST(SkillEngine, DurationAndTimeTransitionsEndPhasesOnTheClock) {
  const Rollout r = run("clock", R"(
[[phases]]
name = "a"
targets = "stand"
duration = 0.1
modules = ["balance"]
next = [{ to = "b", on = "duration" }]
[[phases]]
name = "b"
targets = "stand"
modules = ["balance"]
next = [{ to = "c", on = "time", after = 0.25 }]
[[phases]]
name = "c"
targets = "stand"
modules = ["balance"]
)");
  ASSERT_FALSE(r.e.failed) << r.e.failure;
  const auto& b = r.e.phases.begin;
  ASSERT_EQ(b.size(), 3u);
  EXPECT_NEAR(b[1] - b[0], 0.1, kDt + 1e-9);
  EXPECT_GE(b[1] - b[0], 0.1 - 1e-9);
  EXPECT_NEAR(b[2] - b[1], 0.25, kDt + 1e-9);
}

// A crouch, a push, the flight and the landing: lift-off, the COM's peak and touch-down.
const char* kJump = R"(
[events]
push = "extend"
takeoff = "rise"
peak = "fall"
landing = "land"
[[phases]]
name = "crouch"
targets = "crouch"
gains = "stiff"
duration = 0.4
modules = ["balance"]
next = [{ to = "extend", on = "duration" }]
[[phases]]
name = "extend"
targets = "push"
gains = "stiff"
interpolate = false
next = [{ to = "rise", on = "liftoff", for = 0.01 }, { to = "land", on = "time", after = 0.8, gave_up = true }]
[[phases]]
name = "rise"
targets = "tuck"
gains = "stiff"
duration = { predict = "rise" }
next = [{ to = "land", on = "contact", passes = ["fall"] }, { to = "fall", on = "peak" }]
[[phases]]
name = "fall"
targets = "stand"
gains = "stiff"
duration = { predict = "fall" }
next = [{ to = "land", on = "touchdown" }]
[[phases]]
name = "land"
targets = "crouch"
gains = "stiff"
duration = 0.3
modules = ["balance"]
)";

// The COM height (m) and vertical velocity at each recorded step, from the record's qpos.
TEST(SkillEngine, LiftoffPeakAndTouchdownHappenWhenTheBodyDoesThem) {
  const Rollout r = run("jump", kJump);
  ASSERT_FALSE(r.e.failed) << r.e.failure;
  const PhaseTimes& p = r.e.phases;
  EXPECT_FALSE(r.e.summary.unstable);
  ASSERT_GT(p.takeoff(), 0.4) << "never left the ground";
  ASSERT_GT(p.peak(), p.takeoff());
  ASSERT_GT(p.landing(), p.peak());
  // The flight states the evaluation keeps run from take-off to landing: the root's
  // height peaks between the take-off and the landing, within a few steps of the
  // engine's peak (the COM and the root peak nearly together in a tucked flight).
  const int nq = static_cast<int>(r.e.flight_qpos.size() / r.e.flight_time.size());
  size_t top = 0;
  for (size_t i = 0; i < r.e.flight_time.size(); ++i) {
    if (r.e.flight_qpos[i * nq + 1] > r.e.flight_qpos[top * nq + 1]) top = i;
  }
  EXPECT_NEAR(r.e.flight_time[top], p.peak(), 0.03);
  EXPECT_GT(r.e.flight_qpos[top * nq + 1], r.e.flight_qpos[1] + 0.01) << "a jump rises";
}

TEST(SkillEngine, APushThatNeverLeavesTheGroundGivesUp) {
  // The push held in the crouch never takes off: the time transition marked gave_up ends
  // it 0.8 s after it began, in the land phase, and the rise never begins.
  std::string weak = kJump;
  weak.replace(weak.find("targets = \"push\""), 16, "targets = \"crouch\"");
  const Trace t = simulate("weak", weak, 1.5);
  const int extend = first_step(t, 1), land = first_step(t, 4);
  ASSERT_GE(extend, 0);
  ASSERT_GE(land, 0);
  EXPECT_EQ(first_step(t, 2), -1);
  EXPECT_NEAR(t.time[static_cast<size_t>(land)] - t.time[static_cast<size_t>(extend)], 0.8, kDt + 1e-9);
}

TEST(SkillEngine, BodyContactFeatureAndTurnTransitions) {
  // Lift the left foot (contact_lost), put it down (contact_made), squat until the COM is
  // 12 cm lower (feature), then tilt the pelvis back until the root has turned 0.4 rad.
  const Trace t = simulate("events", R"(
[targets.lift]
hip = { left = { value = 1.2 }, right = { value = 0.0 } }
knee = { left = { value = -1.6 }, right = { value = 0.0 } }
other = 0.0
[targets.squat]
hip = { value = -0.2, world = "parent" }
knee = -1.8
ankle = { value = 0.0, world = "child" }
other = 0.0
[targets.tilt]
hip = { value = 0.9, world = "parent" }
ankle = { value = 0.0, world = "child" }
knee = -1.8
other = 0.0
[[phases]]
name = "stand"
targets = "stand"
duration = 0.2
modules = ["balance"]
next = [{ to = "lift", on = "duration" }]
[[phases]]
name = "lift"
targets = "lift"
duration = 0.3
modules = ["balance"]
next = [{ to = "down", on = "contact_lost", body = "foot_l" }]
[[phases]]
name = "down"
targets = "stand"
duration = 0.3
modules = ["balance"]
next = [{ to = "squat", on = "contact_made", body = "foot_l" }]
[[phases]]
name = "squat"
targets = "squat"
duration = 0.6
modules = ["balance"]
next = [{ to = "limp", on = "feature", feature = "com_z", below = 0.35 }]
[[phases]]
name = "limp"
targets = "tilt"
gains = "stiff"
next = [{ to = "over", on = "turned", angle = 0.4 }]
[[phases]]
name = "over"
targets = "tilt"
gains = "stiff"
)", 3.0);
  ASSERT_EQ(t.phase.back(), 5) << "the machine stopped in phase " << t.phase.back();
  const int lift = first_step(t, 1), down = first_step(t, 2), squat = first_step(t, 3), limp = first_step(t, 4),
            over = first_step(t, 5);
  std::printf("lift %d, down %d, squat %d (COM %.3f m), limp %d (pitch %.3f), over %d\n", lift, down, squat,
              t.com_z[static_cast<size_t>(squat)], limp, t.pitch[static_cast<size_t>(limp)], over);
  // Each transition happens in the first step whose state shows its event (the steps of
  // a phase after its first, where it was entered).
  auto at = [](int step) { return static_cast<size_t>(step); };
  EXPECT_FALSE(t.foot_l[at(down)]);
  for (int i = lift + 1; i < down; ++i) EXPECT_TRUE(t.foot_l[at(i)]) << "step " << i;
  EXPECT_TRUE(t.foot_l[at(squat)]);
  for (int i = down + 1; i < squat; ++i) EXPECT_FALSE(t.foot_l[at(i)]) << "step " << i;
  EXPECT_LE(t.com_z[at(limp)], 0.35);
  EXPECT_GT(t.com_z[at(squat)], 0.38);
  for (int i = squat + 1; i < limp; ++i) EXPECT_GT(t.com_z[at(i)], 0.35) << "step " << i;
  EXPECT_LT(std::fabs(t.pitch[at(limp)]), 0.3);
  EXPECT_GE(std::fabs(t.pitch[at(over)]), 0.4);
  for (int i = limp + 1; i < over; ++i) EXPECT_LT(std::fabs(t.pitch[at(i)]), 0.4) << "step " << i;
}

TEST(SkillEngine, TargetsFollowCurvesAndParametersPerSide) {
  // One long phase whose knee target is a curve and whose hip targets differ by side, the
  // right one a parameter: the commanded targets are those values.
  const std::string rest = R"(
[targets.shaped]
hip = { world = "joint", left = { value = 0.2 }, right = { param = "hip_right", range = [-0.5, 0.5] } }
knee = { curve = [[0.0, 0.0], [0.5, -1.0], [1.0, -0.5]] }
other = 0.0
[[phases]]
name = "only"
targets = "shaped"
duration = 1.0
)";
  const TaskEvaluator ev(tiny_biped::task("shaped", skill(rest)));
  ASSERT_EQ(ev.parameters().size(), 1);
  EXPECT_EQ(ev.parameters().specs()[0].name, "only.hip_right");
  const Character& body = ev.body();
  auto w = ev.make_worker();
  SimWorker& sim = *w;
  const mjModel* m = sim.model();
  mjData* d = sim.data();
  auto c = ev.task().controller_type->make(body, *ev.task().controller_config, {0.3});
  auto* controller = dynamic_cast<SkillController*>(c.get());
  ASSERT_NE(controller, nullptr);
  JointDrive drive = make_drive(body);
  mj_forward(m, d);
  controller->reset(m, d);
  for (double t : {0.25, 0.5, 0.75, 1.0}) {
    d->time = t;
    controller->control(m, d, scan_contacts(m, d, body), drive);
    const std::vector<double>& target = controller->targets();
    const int knee_l = body.groups[static_cast<size_t>(body.find_group("knee"))].joints[0];
    const int hip_l = body.groups[static_cast<size_t>(body.find_group("hip"))].joints[0];
    const int hip_r = body.groups[static_cast<size_t>(body.find_group("hip"))].joints[1];
    const double curve = t <= 0.5 ? -2 * t : -1.0 + (t - 0.5);
    EXPECT_NEAR(target[static_cast<size_t>(knee_l)], curve, 1e-12) << t;
    // Numbers and parameters move linearly from the standing pose to the goal.
    EXPECT_NEAR(target[static_cast<size_t>(hip_l)], t * 0.2, 1e-12) << t;
    EXPECT_NEAR(target[static_cast<size_t>(hip_r)], t * 0.3, 1e-12) << t;
  }
}

TEST(SkillEngine, BalanceHoldsTheComOverTheFeet) {
  // Standing with the pelvis pitched forward: J^T balance keeps the COM over the feet
  // where the same stance without it topples.
  const std::string lean = R"(
[targets.lean]
hip = { value = -0.25, world = "parent" }
ankle = { value = 0.0, world = "child" }
other = 0.0
[[phases]]
name = "lean"
targets = "lean"
duration = 0.5
MODULES
next = [{ to = "hold", on = "duration" }]
[[phases]]
name = "hold"
targets = "lean"
duration = 0.5
MODULES
)";
  auto with = [&](const std::string& modules) {
    std::string text = lean;
    for (size_t at = text.find("MODULES"); at != std::string::npos; at = text.find("MODULES")) text.replace(at, 7, modules);
    return text;
  };
  const Rollout held = run("balanced", with("modules = [\"balance\"]"));
  const Rollout limp = run("unbalanced", with(""));
  ASSERT_FALSE(held.e.failed);
  // Both rollouts run the same targets and gains; only the J^T torques differ. At the
  // end the balanced pelvis (qpos x, z) is still up over the feet; the other is not.
  const size_t nq = static_cast<size_t>(held.record.nq);
  const double* end_held = &held.record.qpos[held.record.qpos.size() - nq];
  const double* end_free = &limp.record.qpos[limp.record.qpos.size() - nq];
  std::printf("pelvis x, z at the end: balanced %.3f %.3f (feet %.3f), without %.3f %.3f (feet %.3f)\n", end_held[0],
              end_held[1], held.e.summary.feet_x, end_free[0], end_free[1], limp.e.summary.feet_x);
  EXPECT_GT(end_held[1], -0.05);  // root z: from the standing height
  EXPECT_NEAR(end_held[0], held.e.summary.feet_x, 0.1);
  EXPECT_GT(std::fabs(end_free[0] - limp.e.summary.feet_x), std::fabs(end_held[0] - held.e.summary.feet_x) + 0.02);
}

TEST(SkillEngine, TorquesStayWithinTheJointLimits) {
  const Rollout r = run("limits", kJump);
  const int nu = r.record.nu;
  ASSERT_GT(r.record.steps(), 100);
  const TaskEvaluator ev(tiny_biped::task("limits_model", skill(kJump)));
  const mjModel* m = ev.model().get();
  for (int s = 0; s < r.record.steps(); ++s) {
    for (int a = 0; a < nu; ++a) {
      EXPECT_LE(std::fabs(r.record.actuator_force[static_cast<size_t>(s * nu + a)]), m->actuator_forcerange[2 * a + 1] + 1e-9);
    }
  }
}

}  // namespace
}  // namespace diverse
