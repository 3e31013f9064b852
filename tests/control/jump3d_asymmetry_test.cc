// The jump3d controller's `asymmetric` option (control/jump3d_controller.h; SPEC 12: "the
// 3D jumps may break left-right symmetry"). Off, the parameter set and the rollouts are
// the ones from before the option; on, every left/right pair's parameter is split into
// NAME_left and NAME_right, the committed input motions (converted: each side the shared
// value) roll out bit for bit as the symmetric ones did, and sides set apart give a motion
// that is no longer mirror-symmetric. The input motions as they were before the option are
// kept in tests/control/data/ (*.m0.symmetric.json), and the converted ones where a search
// has since replaced the task's (*.m0.converted.json).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>

#include "control/jump3d_controller.h"
#include "core/error.h"
#include "physics/rollout.h"
#include "task/evaluate.h"
#include "support/jump3d_variant.h"

namespace diverse {
namespace {

namespace fs = std::filesystem;
const std::string kRoot = DIVERSE_SOURCE_DIR;
const std::string kData = kRoot + "/tests/control/data/";

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// tasks/NAME.toml with absolute paths, its `asymmetric = true` line replaced by `line`, and
// under MuJoCo's damping and stance control's push-off, under which the input motions kept
// here were found (a task file that asks for `damping = "constrained"`,
// `joint_space_extend = true` or `extend_root_kd` has that line dropped).
std::string task_variant(const std::string& name, const std::string& line) {
  std::string t = read(test_files::jump3d_variant(name).string());
  t = std::regex_replace(t, std::regex("\ndamping = \"constrained\""), "\n");
  t = std::regex_replace(t, std::regex("\njoint_space_extend = true"), "\n");
  t = std::regex_replace(t, std::regex("\nextend_root_kd = [0-9.]+"), "\n");
  const std::string on = "asymmetric = true";
  const auto at = t.find(on);
  EXPECT_NE(at, std::string::npos) << name << ".toml does not turn the option on";
  if (at != std::string::npos) t.replace(at, on.size(), line);
  const fs::path dir = fs::temp_directory_path() / ("diverse_asym_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / (name + "_" + std::to_string(std::hash<std::string>{}(line)) + ".toml");
  std::ofstream(p) << t;
  return p.string();
}

Task symmetric_task(const std::string& name) { return load_task(task_variant(name, "asymmetric = false")); }
Task asymmetric_task(const std::string& name) { return load_task(task_variant(name, "asymmetric = true")); }
std::string old_m0(const std::string& name) { return kData + name + ".m0.symmetric.json"; }
// The input motion as first converted for the split controller (each side the shared
// value): the task's m0 until a search of its own replaced it.
std::string converted_m0(const std::string& name, const Task& task) {
  const std::string kept = kData + name + ".m0.converted.json";
  return std::filesystem::exists(kept) ? kept : task.m0;
}

struct Rollout {
  Evaluation e;
  StepRecorder record;
};
Rollout roll(const TaskEvaluator& ev, const std::vector<double>& values) {
  auto worker = ev.make_worker();
  Rollout r;
  EvaluationOptions options;
  options.recorder = &r.record;
  r.e = ev.evaluate(values, *worker, options);
  return r;
}

// FNV-1a over the bytes of every double: a fingerprint of a trajectory, bit for bit.
uint64_t fingerprint(const std::vector<double>& values) {
  uint64_t h = 1469598103934665603ull;
  for (double v : values) {
    unsigned char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    for (unsigned char c : b) h = (h ^ c) * 1099511628211ull;
  }
  return h;
}

std::set<std::string> names_in(const std::string& file) {
  const nlohmann::json j = nlohmann::json::parse(read(file));
  std::set<std::string> names;
  for (const auto& [name, value] : j.at("parameters").items()) names.insert(name);
  return names;
}

bool sided(const std::string& name) {
  auto ends = [&](const std::string& s) { return name.size() > s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0; };
  return ends("_left") || ends("_right");
}

// Off: the parameters are the ones the input motions were found with, in the order and
// with the ranges the default parameter_specs() gives (81 for the human, 69 for the robot).
TEST(Jump3dAsymmetry, OffKeepsTheParameterSet) {
  for (const auto& [task, count] : {std::pair{"jump_backwards", 81}, std::pair{"robot_jump", 69}}) {
    const TaskEvaluator ev(symmetric_task(task));
    const auto specs = ev.parameters().specs();
    ASSERT_EQ(specs.size(), static_cast<size_t>(count)) << task;
    const auto plain = Jump3dController::parameter_specs(ev.body());
    ASSERT_EQ(plain.size(), specs.size());
    std::set<std::string> names;
    for (size_t i = 0; i < specs.size(); ++i) {
      EXPECT_EQ(specs[i].name, plain[i].name);
      EXPECT_EQ(specs[i].lower, plain[i].lower);
      EXPECT_EQ(specs[i].upper, plain[i].upper);
      EXPECT_FALSE(sided(specs[i].name)) << specs[i].name;
      names.insert(specs[i].name);
    }
    EXPECT_EQ(names, names_in(old_m0(task))) << task;
  }
}

// Off: the rollout of the old input motion is the one from before the option existed (its
// qpos trajectory's fingerprint, taken from `diverse simulate` of the build before it,
// which ended a landing at rest on speed alone: balanced_rest off, so that it ends where
// that build's did; taken again when a push-off came to share its force equally between
// the legs, control/stance_controller.h, the one change to the symmetric rollout since).
TEST(Jump3dAsymmetry, OffRollsOutAsBeforeTheOption) {
  for (const auto& [task, expected] : {std::pair{"jump_backwards", 0x2ce82253d3adc0e7ull}, std::pair{"robot_jump", 0x6f01ab53ee5590ecull}}) {
    Task symmetric = symmetric_task(task);
    symmetric.simulation.balanced_rest = false;
    const TaskEvaluator ev(symmetric);
    const Rollout r = roll(ev, ev.load_parameters(old_m0(task)).values());
    EXPECT_EQ(r.e.constraint, 0.0) << task;
    EXPECT_EQ(fingerprint(r.record.qpos), expected) << task << ": 0x" << std::hex << fingerprint(r.record.qpos);
  }
}

// On: every parameter of a pair is two, with the shared parameter's range; what the body
// has one of (the root's and the torso's pitch in stance, the waist, the durations, ...)
// stays one.
TEST(Jump3dAsymmetry, OnSplitsEveryLeftRightPair) {
  for (const auto& [task, count] : {std::pair{"jump_backwards", 145}, std::pair{"robot_jump", 127}}) {
    const TaskEvaluator on(asymmetric_task(task));
    const TaskEvaluator off(symmetric_task(task));
    const ParameterSet split = on.parameters();
    const ParameterSet shared = off.parameters();
    EXPECT_EQ(split.size(), count) << task;
    for (const ParamSpec& s : shared.specs()) {
      const int left = split.find(s.name + "_left"), right = split.find(s.name + "_right");
      if (split.find(s.name) >= 0) {
        EXPECT_LT(left, 0) << s.name;
        continue;
      }
      ASSERT_GE(left, 0) << task << ": " << s.name;
      ASSERT_GE(right, 0) << task << ": " << s.name;
      for (int i : {left, right}) {
        EXPECT_EQ(split.specs()[static_cast<size_t>(i)].lower, s.lower) << s.name;
        EXPECT_EQ(split.specs()[static_cast<size_t>(i)].upper, s.upper) << s.name;
        EXPECT_EQ(split.specs()[static_cast<size_t>(i)].unit, s.unit) << s.name;
      }
    }
  }
  const TaskEvaluator human(asymmetric_task("jump_backwards"));
  const ParameterSet p = human.parameters();
  for (const char* n : {"rise.knee_left", "rise.hip_right", "crouch.foot_left", "crouch.foot_right", "extend.shoulder_left",
                        "fall.elbow_right", "fall.kp_hip_left", "land.kd_ankle_right", "landing.offset_left",
                        "landing.velocity_gain_right", "start.pelvis", "crouch.chest", "rise.waist", "extend.speed"}) {
    EXPECT_GE(p.find(n), 0) << n;
  }
  for (const char* n : {"start.pelvis_left", "rise.waist_left", "rise.knee", "crouch.foot", "land.balance_offset_left"}) {
    EXPECT_LT(p.find(n), 0) << n;
  }
  const TaskEvaluator robot(asymmetric_task("robot_jump"));
  for (const char* n : {"start.torso", "crouch.ankle_left", "rise.toe_right", "extend.foot_left"}) {
    EXPECT_GE(robot.parameters().find(n), 0) << n;
  }
}

// On, the committed input motion (each side the value the shared parameter had) rolls out
// bit for bit as the symmetric controller rolls out the input motion as it was.
TEST(Jump3dAsymmetry, ConvertedInputMotionsRollOutBitForBit) {
  for (const char* task : {"jump_backwards", "robot_jump"}) {
    const TaskEvaluator on(asymmetric_task(task));
    const TaskEvaluator off(symmetric_task(task));
    const ParameterSet converted = on.load_parameters(converted_m0(task, on.task()));
    const ParameterSet old = off.load_parameters(old_m0(task));
    for (const ParamSpec& s : old.specs()) {
      const int i = converted.find(s.name);
      if (i >= 0) {
        EXPECT_EQ(converted.values()[static_cast<size_t>(i)], old.get(s.name)) << s.name;
      } else {
        EXPECT_EQ(converted.get(s.name + "_left"), old.get(s.name)) << s.name;
        EXPECT_EQ(converted.get(s.name + "_right"), old.get(s.name)) << s.name;
      }
    }
    const Rollout a = roll(on, converted.values()), b = roll(off, old.values());
    ASSERT_GT(a.record.steps(), 100) << task;
    EXPECT_EQ(a.record.steps(), b.record.steps()) << task;
    EXPECT_TRUE(a.record.qpos == b.record.qpos) << task << ": the qpos trajectories differ";
    EXPECT_TRUE(a.record.ctrl == b.record.ctrl) << task << ": the controls differ";
    EXPECT_EQ(a.e.constraint, 0.0) << task;
    EXPECT_EQ(a.e.summary.touchdown_feet_x, b.e.summary.touchdown_feet_x) << task;
  }
}

// A file of the shared parameters, read for the split controller, is refused in one line
// that names what to write instead.
TEST(Jump3dAsymmetry, AnOldFileNamesTheSplitParameters) {
  const TaskEvaluator on(asymmetric_task("jump_backwards"));
  try {
    on.load_parameters(old_m0("jump_backwards"));
    ADD_FAILURE() << "a file of shared parameters was accepted";
  } catch (const UserError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_NE(what.find(": parameters.crouch.elbow: expected a known parameter name (unknown parameter; this controller "
                        "has crouch.elbow_left, crouch.elbow_right instead)"),
              std::string::npos)
        << what;
  }
}

// Sides set apart move the body apart: the converted input motion is mirror-symmetric (it
// lands on the heading's line); the same motion with the left arm thrown up through
// push-off and flight (the right as before) swings its shoulders apart by more than a
// radian and touches down off that line, the arm's angular momentum having turned the body.
TEST(Jump3dAsymmetry, SidesSetApartBreakTheMirrorSymmetry) {
  const TaskEvaluator ev(asymmetric_task("jump_backwards"));
  const ParameterSet m0 = ev.load_parameters(converted_m0("jump_backwards", ev.task()));
  ParameterSet apart = m0;
  for (const char* phase : {"extend", "rise", "fall"}) apart.set(std::string(phase) + ".shoulder_left", 2.8);
  const Rollout a = roll(ev, m0.values()), b = roll(ev, apart.values());
  ASSERT_TRUE(a.e.summary.landed && b.e.summary.landed);
  EXPECT_LT(std::abs(a.e.summary.touchdown_feet_y), 1e-3);
  EXPECT_GT(std::abs(b.e.summary.touchdown_feet_y), 0.01);
  // The shoulders' sagittal hinges, left and right, over the rollout.
  const Character& body = ev.body();
  const JointGroup& shoulder = body.groups[static_cast<size_t>(body.find_group(JointRole::kShoulder))];
  const int left = body.joints[static_cast<size_t>(shoulder.joints[0])].qpos;
  const int right = body.joints[static_cast<size_t>(shoulder.joints[1])].qpos;
  auto widest = [&](const StepRecorder& r) {
    double most = 0;
    for (int k = 0; k < r.steps(); ++k) {
      const double* q = r.qpos.data() + static_cast<size_t>(k) * static_cast<size_t>(r.nq);
      most = std::max(most, std::abs(q[left] - q[right]));
    }
    return most;
  };
  EXPECT_LT(widest(a.record), 1e-9);
  EXPECT_GT(widest(b.record), 1.0);
}

}  // namespace
}  // namespace diverse
