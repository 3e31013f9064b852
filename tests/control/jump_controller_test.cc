// The planar human and its jump controller: the model is what section 5 of the paper
// says, every parameter is named and ranged, normalization round-trips, parameter files
// are read strictly, and the controller's phases happen in order with torques that stay
// within the joint limits and never act on the root.
#include "control/jump_controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "character/character.h"
#include "physics/drive.h"
#include "control/parameters.h"
#include "core/error.h"
#include "physics/model.h"
#include "task/evaluate.h"

namespace diverse {
namespace {

const std::string kRoot = DIVERSE_SOURCE_DIR;

TEST(PlanarHuman, ModelMatchesThePaper) {
  const TaskEvaluator ev(load_task(kRoot + "/tasks/jump_high.toml"));
  const mjModel* m = ev.model().get();
  const Character& body = ev.body();
  EXPECT_EQ(body.links.size(), 17u);
  EXPECT_NEAR(body.total_mass, 80.0, 1e-9);
  EXPECT_EQ(body.joints.size(), 16u);
  EXPECT_EQ(body.groups.size(), 10u);  // 10 joint types after left/right symmetry
  EXPECT_NEAR(body.height, 1.60, 1e-9);
  // Torque limits of section 5, as the motors' force ranges.
  const std::map<std::string, double> limits = {
      {"hip", 300}, {"waist_upper", 300}, {"knee", 200}, {"ankle", 200}, {"waist_lower", 200},
      {"shoulder", 200}, {"elbow", 50}, {"wrist", 50}, {"neck", 50}, {"head", 50}};
  for (const CharacterJoint& j : body.joints) {
    EXPECT_EQ(j.torque_limit, limits.at(body.groups[static_cast<size_t>(j.group)].name)) << j.name;
    EXPECT_EQ(m->actuator_forcerange[2 * j.actuator + 1], j.torque_limit) << j.name;
    EXPECT_TRUE(m->actuator_forcelimited[j.actuator]) << j.name;
    EXPECT_LT(j.lower, j.upper);
  }
  // The root is unactuated: every actuator drives one of the 16 hinges.
  for (int a = 0; a < m->nu; ++a) {
    const int joint = m->actuator_trnid[2 * a];
    EXPECT_NE(m->jnt_bodyid[joint], body.root_body) << a;
  }
  EXPECT_EQ(m->nu, 16);
}

std::vector<ParamSpec> human_specs() {
  return TaskEvaluator(load_task(kRoot + "/tasks/jump_high.toml")).parameters().specs();
}

TEST(Parameters, NamedRangedAndNormalized) {
  const auto specs = human_specs();
  EXPECT_GE(specs.size(), 85u);
  EXPECT_LE(specs.size(), 105u);
  std::set<std::string> names;
  for (const ParamSpec& s : specs) {
    EXPECT_TRUE(names.insert(s.name).second) << "duplicate " << s.name;
    EXPECT_LT(s.lower, s.upper) << s.name;
    EXPECT_FALSE(s.unit.empty()) << s.name;
    EXPECT_EQ(s.name.find("neck"), std::string::npos);  // the neck is not optimized
  }
  for (const char* n : {"crouch.knee", "extend.pelvis", "rise.hip", "fall.kd_ankle", "land.kp_hip",
                        "crouch.duration", "landing.velocity_gain"}) {
    EXPECT_TRUE(names.count(n)) << n;
  }
  std::vector<double> v;
  for (const ParamSpec& s : specs) v.push_back(s.lower + 0.3 * (s.upper - s.lower));
  ParameterSet p(specs, v);
  const Eigen::VectorXd x = p.normalized();
  for (int i = 0; i < x.size(); ++i) EXPECT_NEAR(x[i], 0.3, 1e-12);
  ParameterSet q(specs, std::vector<double>(specs.size(), 0.0));
  q.set_normalized(x);
  for (int i = 0; i < p.size(); ++i) EXPECT_NEAR(q.values()[i], v[i], 1e-12);
  // JSON round trip is exact.
  ParameterSet r(specs, std::vector<double>(specs.size(), 0.0));
  r.set_from_json(nlohmann::json::parse(p.to_json().dump()), "p.json");
  EXPECT_EQ(r.values(), p.values());
}

TEST(Parameters, FilesAreReadStrictly) {
  const auto specs = human_specs();
  std::vector<double> v;
  for (const ParamSpec& s : specs) v.push_back(s.lower);
  ParameterSet p(specs, v);
  auto message = [&](nlohmann::json j) {
    try {
      p.set_from_json(j, "m0.json");
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  nlohmann::json good = p.to_json();
  nlohmann::json missing = good;
  missing.erase("crouch.knee");
  EXPECT_EQ(message(missing), "m0.json: parameters.crouch.knee: expected a number in [-2.6, 0] rad");
  nlohmann::json unknown = good;
  unknown["crouch.tail"] = 1;
  EXPECT_EQ(message(unknown),
            "m0.json: parameters.crouch.tail: expected a known parameter name (unknown parameter)");
  nlohmann::json out = good;
  out["crouch.duration"] = 7;
  EXPECT_EQ(message(out), "m0.json: parameters.crouch.duration: expected a number in [0.1, 1] s");
  nlohmann::json text = good;
  text["crouch.duration"] = "long";
  EXPECT_EQ(message(text), "m0.json: parameters.crouch.duration: expected a number in [0.1, 1] s");
}

// The base jump runs the phases in order and keeps every joint torque within its limit.
TEST(JumpController, PhasesInOrderTorquesWithinLimits) {
  const TaskEvaluator ev(load_task(kRoot + "/tasks/jump_high.toml"));
  const ParameterSet p = ev.load_parameters(kRoot + "/tasks/base_jump.json");
  auto worker = ev.make_worker();
  StepRecorder record;
  EvaluationOptions options;
  options.recorder = &record;
  const Evaluation e = ev.evaluate(p.values(), *worker, options);
  ASSERT_FALSE(e.failed);
  const PhaseTimes& t = e.phases;
  EXPECT_EQ(t.begin[kStart], 0.0);
  EXPECT_NEAR(t.begin[kCrouch], p.get("start.duration"), 0.0021);
  EXPECT_NEAR(t.begin[kExtend] - t.begin[kCrouch], p.get("crouch.duration"), 0.0021);
  EXPECT_GT(t.takeoff(), t.begin[kExtend]);
  EXPECT_GT(t.peak(), t.takeoff());
  EXPECT_GT(t.landing(), t.peak());
  EXPECT_GT(e.summary.peak_com_z, 0.95);  // it does leave the ground
  // Motor plus damper (on the end-of-step velocity, as Euler integrates it) within every
  // limit, replayed in plain MuJoCo on a fresh copy of the model.
  mjModel* plain = mj_copyModel(nullptr, ev.model().get());
  const NetTorqueCheck check = check_net_torque(plain, record, driven_joints(plain));
  mj_deleteModel(plain);
  EXPECT_EQ(check.steps, record.steps());
  EXPECT_LE(check.worst_excess, 1e-9);
}

}  // namespace
}  // namespace diverse
