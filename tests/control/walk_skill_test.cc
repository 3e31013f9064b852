// SIMBICON walking (skills/walk3d.toml, skills/robot_walk3d.toml, run by the skill engine
// control/skill_controller.h as the walk tasks name them) on the 3D human and the bird robot, from the
// hand-authored parameters committed as the walk tasks' starting points
// (tasks/silly_walk_start.json, tasks/robot_silly_walk_start.json): from a static start
// in the first state's pose each walks 30 steps without a fall, and over the last 20
// steps every step's length in the heading frame is forward and in a fixed band, the
// pelvis and torso stay within 15 degrees of vertical, the stance sole never leaves the
// floor at a touch-down, every net joint torque stays within its limit at every step, and
// the record replays exactly. A step is a swing-foot touch-down that ends a strike
// phase; its length is the new stance foot's position minus the previous one's, in the
// heading frame at the touch-down.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "character/character.h"
#include "control/heading_frame.h"
#include "control/skill_controller.h"
#include "core/error.h"
#include "core/toml_reader.h"
#include "params/parameters.h"
#include "physics/drive.h"
#include "physics/model.h"
#include "physics/rollout.h"
#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {
namespace {

const std::string kRoot = DIVERSE_SOURCE_DIR;

struct Loaded {
  Task task;  // the walk task of the character, which names its skill
  std::shared_ptr<const CharacterSpec> spec;
  std::shared_ptr<const SharedModel> model;
  Character body;
};

Loaded load(const std::string& name) {
  Loaded l;
  l.task = load_task(kRoot + "/tasks/" + std::string(name == std::string("human3d") ? "silly_walk" : "robot_silly_walk") + ".toml");
  l.spec = std::make_shared<CharacterSpec>(load_character_file(kRoot + "/assets/characters/" + name + ".toml"));
  l.model = SharedModel::from_file(l.spec->model);
  l.body = bind_character(l.spec, l.model->get(), l.spec->model);
  return l;
}

std::vector<ParamSpec> specs_of(const Loaded& l, const Character& body) {
  return l.task.controller_type->parameter_specs(body, *l.task.controller_config);
}

std::unique_ptr<Controller> make(const Loaded& l, const Character& body, const std::vector<double>& values) {
  return l.task.controller_type->make(body, *l.task.controller_config, values);
}

// The values of a {"parameters": {...}} file in parameter order.
std::vector<double> read_values(const Loaded& l, const Character& body, const std::string& file) {
  ParameterSet p(specs_of(l, body), std::vector<double>(specs_of(l, body).size(), 0.0));
  std::ifstream in(file);
  const nlohmann::json j = nlohmann::json::parse(in);
  p.set_from_json(j.at("parameters"), file);
  return p.values();
}

struct Step {
  int leg = 0;             // the leg that touched down
  double time = 0;         // s
  double forward = 0;      // m, heading frame
  double lateral = 0;      // m, heading frame (left positive)
};

struct Outcome {
  std::vector<Step> steps;
  double fell_at = -1;     // s, first contact of a body other than the feet
  std::vector<double> tilt_deg_after;  // per step: the largest pelvis / torso tilt since it
  RolloutStats stats;
  NetTorqueCheck torque;
  double replay_error = 0;
};

double tilt_deg(const mjData* d, int body) {
  return std::acos(std::clamp(d->xmat[9 * body + 8], -1.0, 1.0)) * 180.0 / M_PI;
}

class WalkHooks : public StepHooks {
 public:
  WalkHooks(const Character& body, Controller& walk, JointDrive& drive, int torso, int max_steps,
            Outcome& out)
      : body_(body), walk_(walk), drive_(drive), torso_(torso), max_steps_(max_steps), out_(out) {}

  void control(mjModel* m, mjData* d) override {
    contacts_ = scan_contacts(m, d, body_);
    if (first_) {
      standing_ = standing_frames(m, body_.root_body);
      walk_.reset(m, d);
      const double* f = d->xpos + 3 * body_.feet[1];  // the first stance foot: right
      last_ = {f[0], f[1]};
      first_ = false;
    }
    walk_.control(m, d, contacts_, drive_);
  }

  bool observe(const mjModel*, const mjData* d) override {
    tilt_ = std::max({tilt_, tilt_deg(d, body_.root_body), torso_ >= 0 ? tilt_deg(d, torso_) : 0.0});
    const int state = walk_.phase();
    // A lift phase (0 left, 2 right) begins: the other leg just touched down.
    if (walk_.phase_changed() && (state == 0 || state == 2) && d->time > 0) {
      const int leg = state == 2 ? 0 : 1;  // the leg that just touched down
      const double* f = d->xpos + 3 * body_.feet[static_cast<size_t>(leg)];
      const double h = root_heading(d, body_.root_body, standing_), dx = f[0] - last_[0], dy = f[1] - last_[1];
      out_.steps.push_back({leg, d->time, std::cos(h) * dx + std::sin(h) * dy, -std::sin(h) * dx + std::cos(h) * dy});
      out_.tilt_deg_after.push_back(tilt_);
      tilt_ = 0;
      last_ = {f[0], f[1]};
    }
    if (contacts_.non_foot) {
      out_.fell_at = d->time;
      return true;
    }
    return static_cast<int>(out_.steps.size()) >= max_steps_;
  }

 private:
  const Character& body_;
  Controller& walk_;
  JointDrive& drive_;
  StandingFrames standing_;
  int torso_;
  int max_steps_;
  Outcome& out_;
  ContactState contacts_;
  bool first_ = true;
  std::array<double, 2> last_{};
  double tilt_ = 0;
};

Outcome walk(const Loaded& l, const std::string& params, int steps, double timestep) {
  Outcome out;
  // The model at the timestep asked for: the same MJCF with the option changed.
  std::string xml = l.model->xml();
  const std::string key = "timestep=\"0.002\"";
  const size_t at = xml.find(key);
  EXPECT_NE(at, std::string::npos);
  std::ostringstream ts;
  ts << "timestep=\"" << timestep << "\"";
  xml.replace(at, key.size(), ts.str());
  auto model = SharedModel::from_xml(xml, l.spec->model);
  const Character body = bind_character(l.spec, model->get(), l.spec->model);

  const std::unique_ptr<Controller> c = make(l, body, read_values(l, body, params));
  SimWorker worker(model);
  worker.reset();
  EXPECT_TRUE(c->start_state(worker.model(), worker.data()));
  JointDrive drive = make_drive(body);
  const int torso = mj_name2id(model->get(), mjOBJ_BODY, "torso");
  WalkHooks hooks(body, *c, drive, torso == body.root_body ? -1 : torso, steps, out);
  StepRecorder record;
  out.stats = run_rollout(worker, hooks, static_cast<int>(40.0 / timestep), drive, &record);
  mjModel* plain = mj_copyModel(nullptr, model->get());
  out.torque = check_net_torque(plain, record, drive.joints());
  mj_deleteModel(plain);
  plain = mj_copyModel(nullptr, model->get());
  out.replay_error = replay(plain, record);
  mj_deleteModel(plain);
  return out;
}

struct Expect {
  const char* character;
  const char* params;
  double forward_lo, forward_hi;  // m, every step of the last 20
};

void expect_walks(const Expect& e, double timestep) {
  const Loaded l = load(e.character);
  const Outcome out = walk(l, kRoot + "/tasks/" + e.params, 30, timestep);
  ASSERT_FALSE(out.stats.unstable) << out.stats.instability;
  ASSERT_LT(out.fell_at, 0) << "fell at " << out.fell_at << " s after " << out.steps.size() << " steps";
  ASSERT_EQ(out.steps.size(), 30u);
  for (size_t i = 0; i < out.steps.size(); ++i) {
    EXPECT_EQ(out.steps[i].leg, static_cast<int>(i % 2)) << "step " << i << ": the legs alternate, left first";
  }
  for (size_t i = 10; i < out.steps.size(); ++i) {
    const Step& s = out.steps[i];
    EXPECT_GE(s.forward, e.forward_lo) << "step " << i;
    EXPECT_LE(s.forward, e.forward_hi) << "step " << i;
    EXPECT_LE(std::fabs(s.lateral), 0.5) << "step " << i;
    EXPECT_LE(out.tilt_deg_after[i], 15.0) << "step " << i;
  }
  EXPECT_LE(out.torque.worst_excess, 0.0) << "joint " << out.torque.worst_joint << " at step "
                                          << out.torque.worst_step;
  EXPECT_FALSE(out.torque.blew_up);
  EXPECT_EQ(out.replay_error, 0.0);
}

TEST(WalkSkill, HumanWalksThirtySteps) {
  expect_walks({"human3d", "silly_walk_start.json", 0.5, 1.5}, 0.002);
}
TEST(WalkSkill, HumanWalksAtHalfTheTimestep) {
  expect_walks({"human3d", "silly_walk_start.json", 0.5, 1.5}, 0.001);
}
TEST(WalkSkill, RobotWalksThirtySteps) {
  expect_walks({"robot3d", "robot_silly_walk_start.json", 0.9, 1.5}, 0.002);
}
TEST(WalkSkill, RobotWalksAtHalfTheTimestep) {
  expect_walks({"robot3d", "robot_silly_walk_start.json", 0.9, 1.5}, 0.001);
}

// Every joint but the neck has a target in each of the two states (the stance hip's two
// are the pelvis's), plus the lift duration and four feedback gains.
TEST(WalkSkill, ParametersNamedAndRanged) {
  for (const auto& [name, count] : {std::pair<const char*, size_t>{"human3d", 49}, {"robot3d", 29}}) {
    const Loaded l = load(name);
    const auto specs = specs_of(l, l.body);
    EXPECT_EQ(specs.size(), count) << name;
    std::set<std::string> names;
    for (const ParamSpec& s : specs) {
      EXPECT_TRUE(names.insert(s.name).second) << s.name;
      EXPECT_LT(s.lower, s.upper) << s.name;
      EXPECT_TRUE(std::isfinite(s.lower) && std::isfinite(s.upper)) << s.name;
    }
    for (const char* n : {"lift.pelvis.pitch", "strike.pelvis.roll", "lift.swing.hip", "lift.swing.hip_roll",
                          "strike.stance.knee", "lift.duration", "sagittal.cd", "sagittal.cv",
                          "coronal.cd", "coronal.cv"}) {
      EXPECT_EQ(names.count(n), 1u) << name << ": " << n;
    }
    for (const std::string& n : names) EXPECT_EQ(n.find("neck"), std::string::npos) << n;
    EXPECT_EQ(names.count("lift.stance.hip"), 0u) << "the stance hip holds the pelvis";
  }
  const Loaded h = load("human3d");
  const auto human = specs_of(h, h.body);
  std::set<std::string> names;
  for (const ParamSpec& s : human) names.insert(s.name);
  for (const char* n : {"lift.torso.waist", "lift.torso.waist_roll", "lift.swing_side.shoulder",
                        "lift.stance_side.elbow", "strike.swing.ankle_roll"}) {
    EXPECT_EQ(names.count(n), 1u) << n;
  }
}

// The start state: at rest, the stance (right) sole on the floor, the swing foot above it,
// the root upright at its pelvis target.
TEST(WalkSkill, StartsStaticInTheFirstStatesPose) {
  for (const auto& [name, params] : {std::pair<const char*, const char*>{"human3d", "silly_walk_start.json"},
                                     {"robot3d", "robot_silly_walk_start.json"}}) {
    const Loaded l = load(name);
    const std::unique_ptr<Controller> c = make(l, l.body, read_values(l, l.body, kRoot + "/tasks/" + params));
    SimWorker w(l.model);
    w.reset();
    ASSERT_TRUE(c->start_state(w.model(), w.data()));
    mjData* d = w.data();
    const mjModel* m = w.model();
    mj_forward(m, d);
    for (int i = 0; i < m->nv; ++i) EXPECT_EQ(d->qvel[i], 0.0);
    std::array<double, 2> lowest{INFINITY, INFINITY};
    for (int g = 0; g < m->ngeom; ++g) {
      int side = -1;
      if (!l.body.is_foot_geom(m, g, &side)) continue;
      double lo = 0, hi = 0;
      geom_z_extent(m, d, g, &lo, &hi);
      lowest[static_cast<size_t>(side)] = std::min(lowest[static_cast<size_t>(side)], lo);
    }
    EXPECT_NEAR(lowest[1], 0.0, 1e-9) << name;
    EXPECT_GT(lowest[0], 0.02) << name << ": the swing foot is lifted";
    const double pitch = read_values(l, l.body, kRoot + "/tasks/" + params)[0];
    EXPECT_NEAR(tilt_deg(d, l.body.root_body), std::fabs(pitch) * 180 / M_PI, 0.5) << name;
  }
}

// A task's [controller] table overrides the walk modules' number settings: a stance
// support of 0 lets the bird's stance knee give way under it.
TEST(WalkSkill, ATaskOverridesTheModulesSettings) {
  const std::string task = kRoot + "/tasks/robot_silly_walk.toml";
  const std::string text = [&] {
    std::ifstream in(task);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }();
  const std::string key = "skill = \"../skills/robot_walk3d.toml\"\n";
  ASSERT_NE(text.find(key), std::string::npos);
  std::string weak = text;
  weak.replace(weak.find(key), key.size(), "skill = \"" + kRoot + "/skills/robot_walk3d.toml\"\nsupport = { support = 0.0 }\n");
  for (const char* k : {"character = \"", "m0 = \"", "base = \""}) weak.insert(weak.find(k) + std::string(k).size(), kRoot + "/tasks/");
  const std::string file = testing::TempDir() + "robot_walk_without_support.toml";
  std::ofstream(file) << weak;
  const Task t = load_task(file);
  const auto& config = dynamic_cast<const SkillConfig&>(*t.controller_config);
  EXPECT_EQ(config.skill->modules[static_cast<size_t>(config.skill->module_index("support"))].settings.at("support").number, 0.0);
  // Judged by steps from the other foot where it is (the task measures them from
  // footprints, by which the weaker walk's steps, longer, still pass).
  Task with_task = load_task(task), without_task = t;
  with_task.walk.from_footprint = without_task.walk.from_footprint = false;
  const TaskEvaluator with(with_task), without(without_task);
  const std::vector<double> m0 = with.load_parameters(with_task.m0).values();
  auto w1 = with.make_worker();
  auto w2 = without.make_worker();
  const Evaluation e1 = with.evaluate(m0, *w1), e2 = without.evaluate(m0, *w2);
  EXPECT_EQ(e1.constraint, 0.0);
  EXPECT_GT(e2.constraint, 0.0) << "the walk's steps fall short without the stance support";
  EXPECT_NE(e1.stats.steps, e2.stats.steps);
  // An unknown setting is refused with the task file's name.
  std::string bad = weak;
  bad.replace(bad.find("support = { support = 0.0 }"), 27, "support = { strength = 1.0 }");
  std::ofstream(file) << bad;
  try {
    load_task(file);
    FAIL() << "an unknown setting accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("controller.support.strength: expected a setting of the \"stance_support\" module"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace diverse
