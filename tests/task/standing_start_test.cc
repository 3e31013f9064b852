// A standing jump starts from the ground, flat-footed. Two settings of a task file say so:
// `[simulation] hop_is_fall` (task/task.h): a character that is off the ground for 20 ms
// or more before its extend phase falls, "left the ground before the jump"; and the skill's
// level feet (skills/jump_high.toml, the target set `level`: the ankles hold the soles at
// world pitch 0): the soles stay level in start, crouch and land, and the pose's foot
// values of those phases are not parameters. The high
// jump's earlier input motion, found without either, snapped into its start pose and hopped
// for 0.12 s before it crouched, then crouched and landed on the capsule ends of its feet.
#include <gtest/gtest.h>

#include <mujoco/mujoco.h>

#include <filesystem>
#include <algorithm>
#include <string>

#include "control/skill_controller.h"
#include "core/error.h"
#include "physics/rollout.h"
#include "task/evaluate.h"
#include "task/task.h"
#include "support/skill_variant.h"
#include "support/task_variant.h"

namespace diverse {
namespace {

namespace fs = std::filesystem;
const std::string kSource = DIVERSE_SOURCE_DIR;
const std::string kHops = kSource + "/tests/task/data/jump_high_paper_feet.m0.json";

// The paper's jump (skills/jump2d.toml), and the high jump's skill (skills/jump_high.toml)
// with its feet level but the paper's landing aim and balance servo, as the earlier input
// motion was found with them.
const std::string kPaperFeet = test_files::skill_line("skills/jump2d.toml");
const std::string kLevelFeet = test_files::skill_line("skills/jump_high.toml") +
                               "\nlanding = { at_touchdown = false, reach = 0.0 }"
                               "\nbalance = { kp = 1500.0, kd = 300.0, max_force = 400.0 }";

// jump_high.toml with its skill and its hop_is_fall line replaced by `controller` (top of
// [controller]) and `simulation` (top of [simulation]).
fs::path variant(const std::string& name, const std::string& controller, const std::string& simulation) {
  return test_files::task_variant("jump_high", "standing_start_" + name,
                                  // The earlier motions were found under MuJoCo's damping at 2 ms.
                                  {"skill =", "hop_is_fall =", "damping =", "timestep ="},
                                  {{"controller", controller}, {"simulation", simulation}});
}

// When the phase of that name began in `e` (s).
double begin_of(const Evaluation& e, const std::string& phase) {
  for (size_t k = 0; k < e.phases.names.size(); ++k)
    if (e.phases.names[k] == phase) return e.phases.begin[k];
  ADD_FAILURE() << "no phase " << phase;
  return -1;
}

struct Footing {
  double off_ground = 0;       // s without any contact
  int steps = 0;               // steps from `from` to the extend
  int flat_steps = 0;          // of them, steps with both ends of both soles on the ground
};

// Replays a record and counts, from time `from` until the extend began, the time off the
// ground and the steps on which each foot touches at both its heel and its toe.
Footing footing_before_extend(const TaskEvaluator& ev, const StepRecorder& rec, double extend, double from = 0) {
  mjModel* m = mj_copyModel(nullptr, ev.model().get());
  mjData* d = mj_makeData(m);
  const Character& body = ev.body();
  Footing f;
  for (int s = 0; s < rec.steps() && (s + 1) * rec.timestep < extend; ++s) {
    if ((s + 1) * rec.timestep < from) continue;
    mju_copy(d->qpos, rec.qpos.data() + static_cast<size_t>(s) * rec.nq, rec.nq);
    mju_zero(d->qvel, m->nv);
    mj_forward(m, d);
    ++f.steps;
    if (d->ncon == 0) f.off_ground += rec.timestep;
    bool flat = true;
    for (int foot : body.feet) {
      double lo = 1e9, hi = -1e9;  // contact x relative to the ankle
      for (int c = 0; c < d->ncon; ++c) {
        const int b1 = m->geom_bodyid[d->contact[c].geom1], b2 = m->geom_bodyid[d->contact[c].geom2];
        if (b1 != foot && b2 != foot) continue;
        const double x = d->contact[c].pos[0] - d->xpos[3 * foot];
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
      flat = flat && hi - lo > 0.15;  // heel and toe: the sole's capsule ends are 0.21 m apart
    }
    if (flat) ++f.flat_steps;
  }
  mj_deleteData(d);
  mj_deleteModel(m);
  return f;
}

EvaluationOptions recorded(StepRecorder& rec) {
  EvaluationOptions o;
  o.samples_per_phase = 0;
  o.recorder = &rec;
  return o;
}

TEST(StandingStart, AHopBeforeTheJumpIsAFall) {
  const Task allowed = load_task(variant("hop_allowed", kPaperFeet, "hop_is_fall = false").string());
  const Task refused = load_task(variant("hop_refused", kPaperFeet, "hop_is_fall = true").string());
  const TaskEvaluator ev_allowed(allowed), ev_refused(refused);
  const ParameterSet hops = ev_allowed.load_parameters(kHops);

  StepRecorder rec;
  auto w = ev_allowed.make_worker();
  const Evaluation e = ev_allowed.evaluate(hops.values(), *w, recorded(rec));
  EXPECT_EQ(e.constraint, 0) << "without the rule the hopping jump met the task";
  const double extend = begin_of(e, "extend");
  const Footing f = footing_before_extend(ev_allowed, rec, extend);
  EXPECT_GT(f.off_ground, 0.1) << "it hops before its extend";

  auto w2 = ev_refused.make_worker();
  EvaluationOptions plain;
  plain.samples_per_phase = 0;
  const Evaluation r = ev_refused.evaluate(hops.values(), *w2, plain);
  EXPECT_TRUE(r.fell);
  EXPECT_EQ(r.summary.fall_reason, "left the ground before the jump");
  EXPECT_LT(r.summary.end_time, extend);
  EXPECT_GE(r.constraint, refused.constraints.fall_penalty);
}

// The high jump's crouch under level feet, for the committed input motion and for the
// one before it, found under the default balance servo
// (tests/task/data/jump_high_default_servo.toml).
Footing crouch_of(const std::string& task_file) {
  const Task task = load_task(task_file);
  EXPECT_TRUE(task.simulation.hop_is_fall);
  // Level feet: a skill whose first phase aims the soles level.
  const auto* skill = dynamic_cast<const SkillConfig*>(task.controller_config.get());
  EXPECT_TRUE(skill != nullptr && skill->skill->phases[0].targets == "level") << task_file;
  const TaskEvaluator ev(task);
  StepRecorder rec;
  auto w = ev.make_worker();
  const Evaluation e = ev.evaluate(ev.load_parameters(task.m0).values(), *w, recorded(rec));
  EXPECT_EQ(e.constraint, 0) << task_file;
  // On the ground all the way to the extend (never off it for the rule's 20 ms).
  const Footing f = footing_before_extend(ev, rec, begin_of(e, "extend"));
  EXPECT_LT(f.off_ground, 0.01) << task_file;
  return footing_before_extend(ev, rec, begin_of(e, "extend"), begin_of(e, "crouch"));
}

TEST(StandingStart, TheHighJumpCrouchesFlatFootedAndMeetsTheTask) {
  // Flat on both soles through the crouch, heel and toe down, but for the last steps
  // before the extend, as the heels begin to rise. The committed one, searched with pushes
  // under the stiffer servo, stands on its toes for more of its crouch (measured: 52 of 95
  // steps flat).
  const Footing before = crouch_of(kSource + "/tests/task/data/jump_high_default_servo.toml");
  EXPECT_GE(before.flat_steps, 0.9 * before.steps) << before.flat_steps << " of " << before.steps;
  const Footing crouch = crouch_of(kSource + "/tasks/jump_high.toml");
  EXPECT_GE(crouch.flat_steps, 0.5 * crouch.steps) << crouch.flat_steps << " of " << crouch.steps;

  // The earlier input motion under the paper's foot targets: off the ground or on one end
  // of each sole for most of its crouch.
  const Task paper = load_task(variant("paper_feet", kPaperFeet, "hop_is_fall = false").string());
  const TaskEvaluator ev_paper(paper);
  StepRecorder rec_paper;
  auto w2 = ev_paper.make_worker();
  const Evaluation p = ev_paper.evaluate(ev_paper.load_parameters(kHops).values(), *w2, recorded(rec_paper));
  const Footing fp = footing_before_extend(ev_paper, rec_paper, begin_of(p, "extend"), begin_of(p, "crouch"));
  EXPECT_LT(fp.flat_steps, 0.5 * fp.steps) << fp.flat_steps << " of " << fp.steps;
}

TEST(StandingStart, LevelFeetAreNotParameters) {
  const Task level = load_task(variant("level", kLevelFeet, "hop_is_fall = true").string());
  const Task paper = load_task(variant("paper", kPaperFeet, "hop_is_fall = true").string());
  const auto names = [](const Task& t) {
    std::vector<std::string> n;
    const TaskEvaluator ev(t);
    const ParameterSet p = ev.parameters();
    for (const ParamSpec& s : p.specs()) n.push_back(s.name);
    return n;
  };
  const auto l = names(level), p = names(paper);
  EXPECT_EQ(p.size(), 90u);
  EXPECT_EQ(l.size(), 87u);
  for (const char* gone : {"start.foot", "crouch.foot", "land.foot"}) {
    EXPECT_NE(std::find(p.begin(), p.end(), gone), p.end()) << gone;
    EXPECT_EQ(std::find(l.begin(), l.end(), gone), l.end()) << gone;
  }
  for (const char* kept : {"extend.foot", "rise.ankle", "fall.ankle"}) {
    EXPECT_NE(std::find(l.begin(), l.end(), kept), l.end()) << kept;
  }
}

TEST(StandingStart, BadSettingsAreRefused) {
  auto refused = [](const std::string& controller, const std::string& simulation, const std::string& expected) {
    try {
      load_task(variant("bad", controller, simulation).string());
      ADD_FAILURE() << "expected a UserError for " << controller << " / " << simulation;
    } catch (const UserError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused(kLevelFeet, "hop_is_fall = \"yes\"", "simulation.hop_is_fall");
}

}  // namespace
}  // namespace diverse
