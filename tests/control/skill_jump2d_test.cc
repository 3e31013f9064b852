// The planar human and its jump (skills/jump2d.toml and the skills made from it, run by
// the skill engine): the model is what section 5 of the paper says, every parameter is
// named and ranged, normalization round-trips, parameter files are read strictly, the
// phases happen in order with torques that stay within the joint limits and never act on
// the root, and the flight's timing (a rise or fall duration capped by `at_most`, a rise
// that ends on `turned`) does what the skill file says.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "character/character.h"
#include "physics/drive.h"
#include "params/parameters.h"
#include "control/skill_controller.h"
#include "core/error.h"
#include "physics/model.h"
#include "task/evaluate.h"
#include "support/scratch.h"
#include "support/skill_variant.h"
#include "support/text_files.h"

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
TEST(PlanarJump, PhasesInOrderTorquesWithinLimits) {
  const TaskEvaluator ev(load_task(kRoot + "/tasks/jump_high.toml"));
  const ParameterSet p = ev.load_parameters(kRoot + "/tasks/jump_high_start.json");
  auto worker = ev.make_worker();
  StepRecorder record;
  EvaluationOptions options;
  options.recorder = &record;
  const Evaluation e = ev.evaluate(p.values(), *worker, options);
  ASSERT_FALSE(e.failed);
  const PhaseTimes& t = e.phases;
  ASSERT_EQ(t.names, (std::vector<std::string>{"start", "crouch", "extend", "rise", "fall", "land"}));
  EXPECT_EQ(t.begin[0], 0.0);
  EXPECT_NEAR(t.begin[1], p.get("start.duration"), 0.0021);
  EXPECT_NEAR(t.begin[2] - t.begin[1], p.get("crouch.duration"), 0.0021);
  EXPECT_GT(t.takeoff(), t.begin[2]);
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


// The backflip as its earlier input motion was found (tests/task/data/backflip_explicit.toml:
// the joint drive's explicit way at 1 ms, its skill backflip_open_rotation.skill.toml) with
// `replace` applied to its skill file, written to a scratch directory with the files it
// names. The skill's flight timing, which these variants change:
//   rise  duration = { predict = "rise", at_most = 0.08 }: the tuck reached 0.08 s after
//         take-off, or at the predicted peak if sooner;
//         next on ["peak", "turned"], angle = 3.3: held past the peak until the root has
//         turned 3.3 rad since take-off;
//   fall  duration = { predict = "touchdown", at_most = 0.1 }: open within 0.1 s, or at the
//         predicted touch-down if sooner.
std::string backflip_with(const std::string& name, const std::vector<std::pair<std::string, std::string>>& replace) {
  const std::string data = kRoot + "/tests/task/data/";
  const std::filesystem::path skill =
      test_files::skill_variant("tests/task/data/backflip_open_rotation.skill.toml", "backflip_" + name, replace);
  std::string toml = test_files::read_text(data + "backflip_explicit.toml");
  const std::string key = "skill = \"backflip_open_rotation.skill.toml\"";
  const std::string character = "../../../assets/characters/human2d.toml";
  const std::string base = "../../../tasks/backflip_start.json";
  if (toml.find(key) == std::string::npos || toml.find(character) == std::string::npos ||
      toml.find(base) == std::string::npos)
    return "";
  toml.replace(toml.find(key), key.size(), test_files::skill_line(skill));
  toml.replace(toml.find(character), character.size(), kRoot + "/assets/characters/human2d.toml");
  toml.replace(toml.find(base), base.size(), kRoot + "/tasks/backflip_start.json");
  const std::filesystem::path dir = test_files::scratch_dir(name);
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(data + "backflip_explicit.m0.json", dir / "backflip_explicit.m0.json");
  std::ofstream(dir / "backflip.toml") << toml;
  return (dir / "backflip.toml").string();
}

// The edits: the tuck reached at the predicted peak (no cap), the fall's duration
// predicted from the peak (without or with the 0.1 s cap) or from where it begins
// (uncapped), the rise ended at the peak alone, or only once the root has turned 3.49 rad.
const std::pair<std::string, std::string> kTuckAtPeak = {"{ predict = \"rise\", at_most = 0.08 }", "{ predict = \"rise\" }"};
const std::pair<std::string, std::string> kOpenAtTouchdown = {"{ predict = \"touchdown\", at_most = 0.1 }", "{ predict = \"fall\" }"};
const std::pair<std::string, std::string> kOpenSoon = {"{ predict = \"touchdown\", at_most = 0.1 }",
                                                       "{ predict = \"fall\", at_most = 0.1 }"};
const std::pair<std::string, std::string> kOpenFromHere = {"{ predict = \"touchdown\", at_most = 0.1 }",
                                                           "{ predict = \"touchdown\" }"};
const std::pair<std::string, std::string> kFallAtPeak = {"on = [\"peak\", \"turned\"], angle = 3.3", "on = \"peak\""};
const std::pair<std::string, std::string> kFallWhenTurned = {"angle = 3.3", "angle = 3.49"};

struct Recorded {
  Evaluation e;
  StepRecorder record;
  ParameterSet p;
  // qpos of joint `name` at time t (s) of the recorded rollout.
  double joint_at(const TaskEvaluator& ev, const char* name, double t) const {
    const int j = mj_name2id(ev.model().get(), mjOBJ_JOINT, name);
    const int step = static_cast<int>(std::lround(t / record.timestep));
    return record.qpos[static_cast<size_t>(step * record.nq + ev.model().get()->jnt_qposadr[j])];
  }
};

Recorded simulate_m0(const std::string& task_file) {
  const TaskEvaluator ev(load_task(task_file));
  Recorded r{{}, {}, ev.load_parameters(ev.task().m0)};
  auto worker = ev.make_worker();
  EvaluationOptions options;
  options.recorder = &r.record;
  r.e = ev.evaluate(r.p.values(), *worker, options);
  return r;
}

// The first `seconds` of two recorded rollouts are the same to the bit.
void expect_same_until(const Recorded& a, const Recorded& b, double seconds) {
  const int steps = static_cast<int>(std::lround(seconds / a.record.timestep));
  ASSERT_GE(a.record.steps(), steps);
  ASSERT_GE(b.record.steps(), steps);
  for (int k = 0; k < steps * a.record.nq; ++k)
    ASSERT_EQ(a.record.qpos[static_cast<size_t>(k)], b.record.qpos[static_cast<size_t>(k)]) << "step " << k / a.record.nq;
}

// A predicted duration capped with `at_most`: the rise phase reaches its targets 0.08 s
// after take-off instead of at the predicted peak (a quick tuck); the fall phase 0.1 s
// after the peak instead of at the predicted touch-down (opening in time to land). Before
// the phase they change the motion is the same to the bit; soon after, the knees are much
// nearer the phase's target.
TEST(PlanarJump, CappedFlightDurationsReachTheTargetsSoonerAndChangeNothingBefore) {
  const std::string plain_file = backflip_with("plain", {kTuckAtPeak, kOpenAtTouchdown, kFallAtPeak});
  const std::string tuck_file = backflip_with("tuck_time", {kOpenAtTouchdown, kFallAtPeak});
  const std::string open_file = backflip_with("open_time", {kOpenSoon, kFallAtPeak});
  ASSERT_FALSE(tuck_file.empty());
  const TaskEvaluator ev(load_task(kRoot + "/tasks/backflip.toml"));
  const Recorded plain = simulate_m0(plain_file);
  const Recorded tuck = simulate_m0(tuck_file);
  const Recorded open = simulate_m0(open_file);
  for (const Recorded* r : {&plain, &tuck, &open}) ASSERT_FALSE(r->e.failed);

  const double takeoff = plain.e.phases.takeoff();
  EXPECT_EQ(tuck.e.phases.takeoff(), takeoff);
  expect_same_until(plain, tuck, takeoff);
  const double rise_knee = plain.p.get("rise.knee");
  // From take-off to the peak the tucking knee is nearer its target; 0.12 s in, by more
  // than 0.3 rad (the rise target lies beyond what the knee reaches in the air).
  for (double t = takeoff + 0.02; t < plain.e.phases.peak(); t += 0.02)
    EXPECT_LT(std::fabs(tuck.joint_at(ev, "knee_l", t) - rise_knee), std::fabs(plain.joint_at(ev, "knee_l", t) - rise_knee))
        << t;
  const double t = takeoff + 0.12;
  EXPECT_LT(std::fabs(tuck.joint_at(ev, "knee_l", t) - rise_knee) + 0.3,
            std::fabs(plain.joint_at(ev, "knee_l", t) - rise_knee));

  const double peak = tuck.e.phases.peak();
  EXPECT_EQ(open.e.phases.peak(), peak);
  expect_same_until(tuck, open, peak);
  const double fall_knee = plain.p.get("fall.knee");
  // The knee comes within 0.05 rad of the fall phase's target (following it with a lag)
  // at least 0.05 s sooner when the phase reaches it 0.1 s after the peak.
  auto reaches = [&](const Recorded& r) {
    for (double w = peak; w < r.e.phases.landing(); w += r.record.timestep)
      if (std::fabs(r.joint_at(ev, "knee_l", w) - fall_knee) < 0.05) return w - peak;
    return 1e9;
  };
  const double opened = reaches(open), tucked = reaches(tuck);
  EXPECT_LT(opened, 0.1 + 0.05);
  EXPECT_LT(opened + 0.05, tucked) << opened << " " << tucked;
}


// A rise that ends on ["peak", "turned"]: the tuck lasts past the peak until the root has
// turned `angle` since take-off; only then does the fall phase (opening for the landing)
// begin. Up to the peak nothing changes; the flip turns further in the air.
TEST(PlanarJump, ATurnedTransitionHoldsTheTuckUntilTheRootHasComeRound) {
  const std::string tuck_file = backflip_with("open_rotation_tuck", {kOpenAtTouchdown, kFallAtPeak});
  const std::string late_file = backflip_with("open_rotation", {kOpenFromHere, kFallWhenTurned});
  ASSERT_FALSE(tuck_file.empty());
  const TaskEvaluator ev(load_task(late_file));
  const Recorded tuck = simulate_m0(tuck_file);
  const Recorded late = simulate_m0(late_file);
  ASSERT_FALSE(tuck.e.failed);
  ASSERT_FALSE(late.e.failed);

  const double takeoff = tuck.e.phases.takeoff();
  const double peak = tuck.e.phases.peak();
  EXPECT_EQ(late.e.phases.takeoff(), takeoff);
  expect_same_until(tuck, late, peak);
  // Opened after the peak, when the root had turned 3.49 rad (200 degrees) from take-off
  // (within the degree or so it turns in a step).
  const double opened = late.e.phases.peak();
  EXPECT_GT(opened, peak + 0.02);
  const double pitch0 = late.joint_at(ev, "rooty", takeoff);
  const double turned = std::fabs(late.joint_at(ev, "rooty", opened) - pitch0) * 180 / M_PI;
  EXPECT_NEAR(turned, 3.49 * 180 / M_PI, 2.0);
  // Held tucked longer, it turns further before its feet come down.
  EXPECT_GT(std::fabs(late.e.summary.rotation_flight), std::fabs(tuck.e.summary.rotation_flight) + 0.2);
}

// The engine wraps angles to [-pi, pi] with std::remainder only when they lie outside
// (skill_wrap, control/skill_controller.h):
// inside, remainder(a, 2 pi) is a itself, bit for bit, which this checks on the edges and
// on a million angles, so the shortcut changes no motion.
TEST(PlanarJump, AnAngleWithinPiIsItsOwnRemainder) {
  std::vector<double> angles = {0.0, -0.0, M_PI, -M_PI, std::nextafter(M_PI, 0.0), std::nextafter(-M_PI, 0.0),
                                1e-300, -1e-300, 0.5 * M_PI, -0.5 * M_PI};
  unsigned long long state = 88172645463325252ULL;
  for (int k = 0; k < 1000000; ++k) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    angles.push_back((static_cast<double>(state >> 11) * 0x1.0p-53 * 2 - 1) * M_PI);
  }
  int differ = 0, wrapped_differ = 0;
  for (double a : angles) {
    const double r = std::remainder(a, 2 * M_PI), w = skill_wrap(a);
    if (std::memcmp(&r, &a, sizeof a) != 0) ++differ;
    if (std::memcmp(&r, &w, sizeof a) != 0) ++wrapped_differ;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(wrapped_differ, 0);
  // Just outside, it wraps.
  EXPECT_LT(std::remainder(std::nextafter(M_PI, 4.0), 2 * M_PI), 0.0);
  for (double a : {std::nextafter(M_PI, 4.0), 4.0, -7.5, 20.0}) EXPECT_EQ(skill_wrap(a), std::remainder(a, 2 * M_PI)) << a;
}

}  // namespace
}  // namespace diverse
