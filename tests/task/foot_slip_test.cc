// The foot-slip measure (task/foot_slip.h) on a planar box on the floor, driven by motors
// on its root slides: pushed along the floor it slides by what Coulomb friction says and by
// exactly what its root moved; at rest it does not slide; tipped over one edge it pivots
// about still points and does not slide either, though it moves; lifted and set down it
// has two stances. On a committed input motion, both sides' stances are found.
#include "task/foot_slip.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "physics/model.h"
#include "support/task_variant.h"
#include "task/evaluate.h"
#include "task/task.h"
#include "task/term_foot_slip.h"

namespace diverse {
namespace {

const std::string kTasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";

// A 20 kg box, 0.2 x 0.1 m (half sizes hx, hz), on a planar root: slide x, slide z, hinge
// y, with force motors on the two slides. Friction 0.5 (pyramidal cone, MuJoCo's default).
std::string box_model(double hx, double hz, double friction) {
  return R"(
<mujoco>
  <option timestep="0.002" integrator="Euler"/>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1" friction=")" + std::to_string(friction) + R"( 0.005 0.0001"/>
    <body name="box" pos="0 0 )" + std::to_string(hz) + R"(">
      <joint name="x" type="slide" axis="1 0 0"/>
      <joint name="z" type="slide" axis="0 0 1"/>
      <joint name="pitch" type="hinge" axis="0 1 0"/>
      <geom name="foot" type="box" size=")" + std::to_string(hx) + " 0.1 " + std::to_string(hz) +
         R"(" mass="20" friction=")" + std::to_string(friction) + R"( 0.005 0.0001"/>
    </body>
  </worldbody>
  <actuator>
    <motor joint="x"/>
    <motor joint="z"/>
  </actuator>
</mujoco>)";
}

constexpr double kG = 9.81;
constexpr double kMass = 20;

// A record of `steps` steps with the motors' forces given per step; no recorded qpos
// (the measure replays the inputs).
StepRecorder record_of(const mjModel* m, int steps, const std::vector<double>& qvel0,
                       const std::function<std::array<double, 2>(int)>& forces) {
  StepRecorder r;
  r.nq = m->nq;
  r.nu = m->nu;
  r.timestep = m->opt.timestep;
  r.qpos0.assign(m->qpos0, m->qpos0 + m->nq);
  r.qvel0 = qvel0;
  for (int k = 0; k < steps; ++k) {
    const std::array<double, 2> f = forces(k);
    r.ctrl.push_back(f[0]);
    r.ctrl.push_back(f[1]);
  }
  return r;
}

struct Measured {
  FootSlip slip;
  std::vector<double> qpos;  // at the end
};

Measured measure(const std::string& xml, const StepRecorder& record) {
  const auto model = SharedModel::from_xml(xml, "box");
  mjModel* m = mj_copyModel(nullptr, model->get());
  std::vector<int> sides(static_cast<size_t>(m->ngeom), kSceneGeom);
  sides[static_cast<size_t>(mj_name2id(m, mjOBJ_GEOM, "foot"))] = 0;
  Measured out;
  out.slip = measure_foot_slip(m, record, sides);
  // The root's own motion, from a second plain replay of the same inputs.
  mjData* d = mj_makeData(m);
  replay_each_step(m, d, record, record.steps(), [](int, const mjData*) { return true; });
  out.qpos.assign(d->qpos, d->qpos + m->nq);
  mj_deleteData(d);
  mj_deleteModel(m);
  return out;
}

TEST(FootSlip, ABoxPushedAlongTheFloorSlidesAsCoulombFrictionSays) {
  const std::string xml = box_model(0.1, 0.05, 0.5);
  const auto model = SharedModel::from_xml(xml, "box");
  // 1 s of a 150 N push against 0.5 x 196 N of friction: a = F/m - mu g from rest.
  constexpr double kPush = 150, kMu = 0.5, kTime = 1.0;
  const int steps = static_cast<int>(std::lround(kTime / model->get()->opt.timestep));
  const StepRecorder r = record_of(model->get(), steps, {0, 0, 0}, [](int) { return std::array<double, 2>{kPush, 0}; });
  const Measured out = measure(xml, r);
  const FootSlip::Side& foot = out.slip.sides[0];
  ASSERT_FALSE(out.slip.blew_up);
  EXPECT_EQ(out.slip.steps, steps);
  ASSERT_EQ(foot.stances.size(), 1u);  // on the floor throughout
  EXPECT_TRUE(out.slip.sides[1].stances.empty());
  const double moved = out.qpos[0] - model->get()->qpos0[0];
  // Everything the box moved, it slid: the integral of the slowest contact point's speed
  // is the root's displacement, within what the box's rocking on MuJoCo's soft contacts
  // (it hops on its corners by a fraction of a millimetre) and the last steps (slid since
  // the last loaded step, when the record ends) leave out: 0.5 %.
  EXPECT_NEAR(foot.total, moved, 5e-3 * moved);
  // And what Coulomb's law says, x = (F/m - mu g) t^2 / 2 = 1.30 m, within MuJoCo's soft
  // contact (a friction force slightly below mu N while sliding: 2 %).
  const double expected = 0.5 * (kPush / kMass - kMu * kG) * kTime * kTime;
  EXPECT_NEAR(foot.total, expected, 0.02 * expected);
  EXPECT_DOUBLE_EQ(foot.largest, foot.total);
  EXPECT_DOUBLE_EQ(foot.mean, foot.total);
  // The speed at the end: a t, and the rocking's turn rate times the corner's height above
  // the centre on top of it (measured: 5 %).
  const double at_end = (kPush / kMass - kMu * kG) * kTime;
  EXPECT_GT(foot.max_speed, 0.98 * at_end);
  EXPECT_LT(foot.max_speed, 1.08 * at_end);
  EXPECT_GT(foot.max_speed_time, 0.9 * kTime);
}

TEST(FootSlip, ABoxAtRestDoesNotSlide) {
  const std::string xml = box_model(0.1, 0.05, 0.5);
  const auto model = SharedModel::from_xml(xml, "box");
  const StepRecorder r = record_of(model->get(), 500, {0, 0, 0}, [](int) { return std::array<double, 2>{0, 0}; });
  const Measured out = measure(xml, r);
  ASSERT_EQ(out.slip.sides[0].stances.size(), 1u);
  EXPECT_LT(out.slip.sides[0].total, 1e-6);
}

TEST(FootSlip, ABoxHeldByStaticFrictionCreepsAsMuJoCosSoftContactLetsIt) {
  const std::string xml = box_model(0.1, 0.05, 0.5);
  const auto model = SharedModel::from_xml(xml, "box");
  // Pushed with 60 N, below the 98 N that friction holds: a rigid Coulomb contact would
  // not move; MuJoCo's soft contact (its friction is a stiff spring-damper, not a lock)
  // lets it creep at about 1 mm/s, and the measure finds what the root moved.
  const StepRecorder r = record_of(model->get(), 500, {0, 0, 0}, [](int) { return std::array<double, 2>{60, 0}; });
  const Measured out = measure(xml, r);
  const double moved = out.qpos[0] - model->get()->qpos0[0];
  ASSERT_EQ(out.slip.sides[0].stances.size(), 1u);
  EXPECT_GT(moved, 1e-4);
  EXPECT_LT(moved, 2e-3);
  EXPECT_NEAR(out.slip.sides[0].total, moved, 0.1 * moved);
}

TEST(FootSlip, ABoxPivotingOnAnEdgeDoesNotSlide) {
  // A tall box (0.1 x 0.3 m) tipped over its +x edge: its centre starts turning about that
  // edge at 3 rad/s (v = w x r for r from the edge to the centre, enough to go over), with
  // friction 1.5 holding the edge. Only the edge carries load, and it stays put.
  const std::string xml = box_model(0.05, 0.15, 1.5);
  const auto model = SharedModel::from_xml(xml, "box");
  constexpr double w = 3;
  const StepRecorder r =
      record_of(model->get(), 100, {w * 0.15, w * 0.05, w}, [](int) { return std::array<double, 2>{0, 0}; });
  const Measured out = measure(xml, r);
  const double centre_moved = out.qpos[0] - model->get()->qpos0[0];
  EXPECT_GT(centre_moved, 0.05);        // the box moved ...
  EXPECT_GT(out.qpos[2], 0.4);          // ... turning about its edge ...
  ASSERT_EQ(out.slip.sides[0].stances.size(), 1u);
  EXPECT_LT(out.slip.sides[0].total, 2e-3);  // ... which did not slide
}

TEST(FootSlip, ALiftIsANewStanceAndTheImpactIsLeftOut) {
  const std::string xml = box_model(0.1, 0.05, 0.5);
  const auto model = SharedModel::from_xml(xml, "box");
  // 0.1 s lifting with 400 N (twice its weight), then nothing: off the floor for about
  // 0.2 s, and down again. A push along x only while it is in the air.
  const StepRecorder r = record_of(model->get(), 400, {0, 0, 0}, [](int k) {
    return std::array<double, 2>{k >= 60 && k < 120 ? 100.0 : 0.0, k < 50 ? 400.0 : 0.0};
  });
  const Measured out = measure(xml, r);
  const FootSlip::Side& foot = out.slip.sides[0];
  ASSERT_EQ(foot.stances.size(), 2u);
  EXPECT_EQ(foot.stances[0].begin, 0);
  EXPECT_GT(foot.stances[1].begin, foot.stances[0].end + 0.1);
  // It landed moving along x at 0.6 m/s (100 N for 0.12 s) and slid to a stop: what it
  // slid after the 10 ms impact, the landing speed's v^2 / (2 mu g) at most.
  EXPECT_GT(foot.stances[1].slide, 0.001);
  EXPECT_LT(foot.stances[1].slide, 0.6 * 0.6 / (2 * 0.5 * kG));
  EXPECT_NEAR(foot.total, foot.stances[0].slide + foot.stances[1].slide, 1e-12);
  EXPECT_DOUBLE_EQ(foot.largest, std::max(foot.stances[0].slide, foot.stances[1].slide));
}

TEST(FootSlip, ACommittedInputMotionHasStancesOnBothSides) {
  const TaskEvaluator ev(load_task(kTasks + "jump_high.toml"));
  StepRecorder record;
  EvaluationOptions options;
  options.samples_per_phase = 0;
  options.recorder = &record;
  const auto worker = ev.make_worker();
  const Evaluation e = ev.evaluate(ev.load_parameters(ev.task().m0).values(), *worker, options);
  ASSERT_FALSE(e.fell);
  mjModel* m = mj_copyModel(nullptr, ev.model().get());
  const FootSlip slip = measure_foot_slip(m, record, ev.body());
  mj_deleteModel(m);
  EXPECT_FALSE(slip.blew_up);
  // Standing and crouching, then landing and standing: two stances on each side.
  for (const FootSlip::Side& side : slip.sides) {
    ASSERT_EQ(side.stances.size(), 2u);
    EXPECT_EQ(side.stances[0].begin, 0);
    EXPECT_LT(side.largest, 0.05);
  }
  const nlohmann::json j = foot_slip_json(slip);
  EXPECT_EQ(j["left"]["stances"], 2);
  EXPECT_EQ(j["right"]["stance_slides"].size(), 2u);
  EXPECT_DOUBLE_EQ(j["largest_per_stance"].get<double>(), slip.largest());
}

// The task's bound (task/term_foot_slip.h) measures the rollout step by step as the
// replay measures its record: the same largest stance, to the last bit, and a term
// "foot_slip" of K_c d^2 for the excess d only when the bound is broken.
TEST(FootSlip, ATaskBoundMeasuresTheRolloutAsTheReplayDoes) {
  auto rollout = [](const std::string& name, const std::string& bound, StepRecorder* record) {
    const auto file = test_files::task_variant("jump_high", name, {"foot_slip ="}, {{"constraints", "foot_slip = { per_stance = " + bound + " }"}});
    const TaskEvaluator ev(load_task(file.string()));
    EXPECT_NE(ev.task().constraints.find<FootSlipConstraint>(), nullptr);
    EvaluationOptions options;
    options.samples_per_phase = 0;
    options.recorder = record;
    const auto worker = ev.make_worker();
    Evaluation e = ev.evaluate(ev.load_parameters(ev.task().m0).values(), *worker, options);
    double replayed = -1;
    if (record != nullptr) {
      mjModel* m = mj_copyModel(nullptr, ev.model().get());
      replayed = measure_foot_slip(m, *record, ev.body()).largest();
      mj_deleteModel(m);
    }
    return std::make_pair(e, replayed);
  };
  StepRecorder record;
  const auto [loose, replayed] = rollout("slip_loose", "0.05", &record);
  ASSERT_FALSE(loose.fell);
  EXPECT_GT(loose.summary.foot_slip, 0.002);
  EXPECT_EQ(loose.summary.foot_slip, replayed);
  EXPECT_EQ(loose.constraint, 0);
  const auto term = [](const Evaluation& e) {
    for (const ConstraintTerm& t : e.report.terms)
      if (t.name == "foot_slip") return t;
    ADD_FAILURE() << "no foot_slip term";
    return ConstraintTerm{};
  };
  EXPECT_EQ(term(loose).penalty, 0);
  // The slack of the bound, for the input-motion search: the share left unused, as 10 cm.
  const Task task;
  FootSlipConstraint bound("constraints.foot_slip");
  bound.per_stance = 0.05;
  EXPECT_NEAR(bound.margin(task, loose.summary), 0.1 * (1 - loose.summary.foot_slip / 0.05), 1e-15);
  bound.per_stance = 0;  // no slide allowed: no slack to keep away from
  EXPECT_EQ(bound.margin(task, loose.summary), INFINITY);
  // A bound 1 mm below what the input motion slides: broken by 1 mm.
  std::ostringstream tight;
  tight.precision(17);
  tight << loose.summary.foot_slip - 0.001;
  const auto [broken, unused] = rollout("slip_tight", tight.str(), nullptr);
  (void)unused;
  EXPECT_EQ(broken.summary.foot_slip, loose.summary.foot_slip);  // the same rollout
  EXPECT_NEAR(term(broken).violation, 0.001, 1e-12);
  EXPECT_NEAR(broken.constraint, 5000.0 * 1e-6, 1e-9);
}

TEST(FootSlip, ATaskBoundOutOfRangeOrWithAnUnknownKeyIsNamed) {
  const auto bad = [](const std::string& name, const std::string& line) {
    const auto file = test_files::task_variant("jump_high", name, {"foot_slip ="}, {{"constraints", line}});
    try {
      load_task(file.string());
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(bad("slip_negative", "foot_slip = { per_stance = -0.01 }").find("constraints.foot_slip.per_stance: expected"),
            std::string::npos)
      << bad("slip_negative", "foot_slip = { per_stance = -0.01 }");
  EXPECT_NE(bad("slip_unknown", "foot_slip = { largest = 0.02 }").find("constraints.foot_slip"), std::string::npos)
      << bad("slip_unknown", "foot_slip = { largest = 0.02 }");
}

}  // namespace
}  // namespace diverse
