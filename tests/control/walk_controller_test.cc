// SIMBICON walking (control/walk_controller.h) on the 3D human and the bird robot, from the
// hand-authored parameters committed as the walk tasks' starting points
// (tasks/silly_walk_start.json, tasks/robot_silly_walk_start.json): from a static start
// in the first state's pose each walks 30 steps without a fall, and over the last 20
// steps every step's length in the heading frame is forward and in a fixed band, the
// pelvis and torso stay within 15 degrees of vertical, the stance sole never leaves the
// floor at a touch-down, every net joint torque stays within its limit at every step, and
// the record replays exactly. A step is a swing-foot touch-down that ends a strike
// state; its length is the new stance foot's position minus the previous one's, in the
// heading frame at the touch-down.
#include "control/walk_controller.h"

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
#include "control/parameters.h"
#include "core/error.h"
#include "core/toml_reader.h"
#include "physics/drive.h"
#include "physics/model.h"
#include "physics/rollout.h"

namespace diverse {
namespace {

const std::string kRoot = DIVERSE_SOURCE_DIR;

struct Loaded {
  std::shared_ptr<const CharacterSpec> spec;
  std::shared_ptr<const SharedModel> model;
  Character body;
};

Loaded load(const std::string& name) {
  Loaded l;
  l.spec = std::make_shared<CharacterSpec>(load_character_file(kRoot + "/assets/characters/" + name + ".toml"));
  l.model = SharedModel::from_file(l.spec->model);
  l.body = bind_character(l.spec, l.model->get(), l.spec->model);
  return l;
}

// The values of a {"parameters": {...}} file in parameter_specs() order.
std::vector<double> read_values(const Character& body, const std::string& file) {
  ParameterSet p(WalkController::parameter_specs(body),
                 std::vector<double>(WalkController::parameter_specs(body).size(), 0.0));
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
  WalkHooks(const Character& body, WalkController& walk, JointDrive& drive, int torso, int max_steps,
            Outcome& out)
      : body_(body), walk_(walk), drive_(drive), torso_(torso), max_steps_(max_steps), out_(out) {}

  void control(mjModel* m, mjData* d) override {
    contacts_ = scan_contacts(m, d, body_);
    if (first_) {
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
    if (walk_.phase_changed() && (state == kLeftLift || state == kRightLift) && d->time > 0) {
      const int leg = state == kRightLift ? 0 : 1;  // the leg that just touched down
      const double* f = d->xpos + 3 * body_.feet[static_cast<size_t>(leg)];
      const double h = walk_.heading(), dx = f[0] - last_[0], dy = f[1] - last_[1];
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
  WalkController& walk_;
  JointDrive& drive_;
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

  WalkControllerConfig config;
  WalkController c(body, config);
  c.set_parameters(read_values(body, params));
  SimWorker worker(model);
  worker.reset();
  EXPECT_TRUE(c.start_state(worker.model(), worker.data()));
  JointDrive drive = make_drive(body);
  const int torso = mj_name2id(model->get(), mjOBJ_BODY, "torso");
  WalkHooks hooks(body, c, drive, torso == body.root_body ? -1 : torso, steps, out);
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

TEST(WalkController, HumanWalksThirtySteps) {
  expect_walks({"human3d", "silly_walk_start.json", 0.5, 1.5}, 0.002);
}
TEST(WalkController, HumanWalksAtHalfTheTimestep) {
  expect_walks({"human3d", "silly_walk_start.json", 0.5, 1.5}, 0.001);
}
TEST(WalkController, RobotWalksThirtySteps) {
  expect_walks({"robot3d", "robot_silly_walk_start.json", 0.9, 1.5}, 0.002);
}
TEST(WalkController, RobotWalksAtHalfTheTimestep) {
  expect_walks({"robot3d", "robot_silly_walk_start.json", 0.9, 1.5}, 0.001);
}

// Every joint but the neck has a target in each of the two states (the stance hip's two
// are the pelvis's), plus the lift duration and four feedback gains.
TEST(WalkController, ParametersNamedAndRanged) {
  for (const auto& [name, count] : {std::pair<const char*, size_t>{"human3d", 49}, {"robot3d", 29}}) {
    const Loaded l = load(name);
    const auto specs = WalkController::parameter_specs(l.body);
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
  const auto human = WalkController::parameter_specs(load("human3d").body);
  std::set<std::string> names;
  for (const ParamSpec& s : human) names.insert(s.name);
  for (const char* n : {"lift.torso.waist", "lift.torso.waist_roll", "lift.swing_side.shoulder",
                        "lift.stance_side.elbow", "strike.swing.ankle_roll"}) {
    EXPECT_EQ(names.count(n), 1u) << n;
  }
}

// The start state: at rest, the stance (right) sole on the floor, the swing foot above it,
// the root upright at its pelvis target.
TEST(WalkController, StartsStaticInTheFirstStatesPose) {
  for (const auto& [name, params] : {std::pair<const char*, const char*>{"human3d", "silly_walk_start.json"},
                                     {"robot3d", "robot_silly_walk_start.json"}}) {
    const Loaded l = load(name);
    WalkController c(l.body, WalkControllerConfig{});
    c.set_parameters(read_values(l.body, kRoot + "/tasks/" + params));
    SimWorker w(l.model);
    w.reset();
    ASSERT_TRUE(c.start_state(w.model(), w.data()));
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
    const double pitch = read_values(l.body, kRoot + "/tasks/" + params)[0];
    EXPECT_NEAR(tilt_deg(d, l.body.root_body), std::fabs(pitch) * 180 / M_PI, 0.5) << name;
  }
}

TEST(WalkController, ConfigReadStrictly) {
  const WalkControllerType type;
  const toml::table ok = toml::parse("type = \"walk3d\"\nroot_kp = 2000\nstance_support = 0.5\n");
  const auto config = type.read_config(TomlReader("walk.toml", ok, "controller"));
  const auto& c = dynamic_cast<const WalkControllerConfig&>(*config);
  EXPECT_EQ(c.root_kp, 2000);
  EXPECT_EQ(c.stance_support, 0.5);
  const toml::table bad = toml::parse("type = \"walk3d\"\nroot_gain = 2000\n");
  try {
    type.read_config(TomlReader("walk.toml", bad, "controller"));
    FAIL() << "unknown key accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("walk.toml: controller.root_gain: expected no such key"), std::string::npos)
        << e.what();
  }
}

TEST(WalkController, RefusesAPlanarCharacter) {
  const Loaded l = load("human2d");
  try {
    WalkControllerType().check(l.body, "walk.toml");
    FAIL() << "a planar character accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("walk.toml: controller.type: expected a character with a free root"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace diverse
