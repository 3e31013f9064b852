// The jump controller of characters with a free root ("jump3d"): its parameters are named
// and ranged for each character, it refuses characters it cannot drive, its leg placement
// points the legs exactly where it means to, and a hand-authored jump of each character
// goes through every phase with every torque within the joint limits and none on the root.
#include "control/jump3d_controller.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <thread>

#include "character/character.h"
#include "core/error.h"
#include "physics/drive.h"
#include "physics/model.h"
#include "task/evaluate.h"
#include "support/jump3d_variant.h"

namespace diverse {
namespace {

namespace fs = std::filesystem;
const std::string kRoot = DIVERSE_SOURCE_DIR;

std::set<std::string> names_of(const std::vector<ParamSpec>& specs) {
  std::set<std::string> names;
  for (const ParamSpec& s : specs) {
    EXPECT_TRUE(names.insert(s.name).second) << "duplicate " << s.name;
    EXPECT_LT(s.lower, s.upper) << s.name;
    EXPECT_FALSE(s.unit.empty()) << s.name;
  }
  return names;
}

// Per phase the sagittal groups but neck and wrists (stance phases name the tracked links
// by what they are), and kp, kd of hips, knees and ankles; then nine more. (Left and right
// sharing their parameters; tests/control/jump3d_asymmetry_test.cc splits them.)
TEST(Jump3dParameters, NamedAndRangedForTheHuman) {
  const TaskEvaluator ev(load_task(test_files::jump3d_variant("jump_backwards").string()));
  const auto specs = Jump3dController::parameter_specs(ev.body());
  EXPECT_EQ(specs.size(), 6u * (6 + 6) + 9);
  const auto names = names_of(specs);
  for (const char* n : {"start.pelvis", "crouch.knee", "crouch.foot", "crouch.chest", "extend.shoulder",
                        "extend.lean", "extend.speed", "rise.hip", "rise.ankle", "rise.waist", "fall.elbow", "land.kp_hip",
                        "land.kd_ankle", "crouch.duration", "landing.velocity_gain"}) {
    EXPECT_TRUE(names.count(n)) << n;
  }
  for (const std::string& n : names) {
    EXPECT_EQ(n.find("neck"), std::string::npos) << n;
    EXPECT_EQ(n.find("wrist"), std::string::npos) << n;
    EXPECT_EQ(n.find("roll"), std::string::npos) << n;  // coronal hinges are not parameters
  }
  // A joint angle's range is its joint's.
  for (const ParamSpec& s : specs) {
    if (s.name == "rise.knee") {
      EXPECT_EQ(s.lower, -2.6);
      EXPECT_EQ(s.upper, 0.0);
    }
  }
}

TEST(Jump3dParameters, NamedAndRangedForTheRobot) {
  const TaskEvaluator ev(load_task(test_files::jump3d_variant("robot_jump").string()));
  const auto specs = Jump3dController::parameter_specs(ev.body());
  EXPECT_EQ(specs.size(), 6u * (4 + 6) + 9);
  const auto names = names_of(specs);
  // The bird's root is its body, "torso"; its feet pitch at the toe joints; its ankle is a
  // joint angle in every phase.
  for (const char* n : {"start.torso", "crouch.ankle", "crouch.foot", "extend.knee", "rise.toe", "fall.hip"}) {
    EXPECT_TRUE(names.count(n)) << n;
  }
  EXPECT_FALSE(names.count("crouch.chest"));  // no waist
}

std::string write_task(const std::string& character, const std::string& controller) {
  const fs::path dir = fs::temp_directory_path() / ("diverse_jump3d_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / "t.toml";
  std::ofstream(p) << "name = \"t\"\ncharacter = \"" << kRoot << "/assets/characters/" << character
                   << "\"\nmetric = \"md\"\nvariations = 4\nm0 = \"t.m0.json\"\n[controller]\ntype = \""
                   << controller << "\"\n[constraints]\nweight = 5000.0\nfall_penalty = 100000.0\n"
                   << "landing = { center = 0.5, radius = 0.25 }\n";
  return p.string();
}

TEST(Jump3dController, RefusesAPlanarCharacter) {
  const std::string path = write_task("human2d.toml", "jump3d");
  try {
    TaskEvaluator ev(load_task(path));
    ADD_FAILURE() << "jump3d accepted a planar character";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": controller.type: expected a character with a free root for "
                                            "\"jump3d\", but the character " + kRoot +
                                            "/assets/characters/human2d.toml has a planar root (use \"jump2d\")");
  }
}

TEST(Jump3dController, ReadsItsOwnKeysStrictly) {
  const std::string path = write_task("human3d.toml", "jump3d\"\nbounce = \"2");
  try {
    load_task(path);
    ADD_FAILURE() << "an unknown key was accepted";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": controller.bounce: expected no such key (unknown key; known keys: "
                                            "type, landing_control, landing_height, extend_timeout, com_kp, com_kd, "
                                            "asymmetric, yaw_kp, yaw_kd, neck_attitude_kp, neck_attitude_kd, "
                                            "land_swing_placement, joint_space_extend, extend_root_kd)");
  }
}

// The leg placement's hip angles, put into the model, point the leg (hip to foot joint)
// exactly along the asked direction, for both characters and both legs, whatever the knee.
TEST(Jump3dController, HipAnglesPointTheLegWhereAsked) {
  for (const char* task : {"jump_backwards", "robot_jump"}) {
    const TaskEvaluator ev(load_task(test_files::jump3d_variant(task).string()));
    const mjModel* m = ev.model().get();
    const Character& body = ev.body();
    mjData* d = mj_makeData(m);
    const int hip_g = body.find_group(JointRole::kHip, JointPlane::kSagittal);
    const int roll_g = body.find_group(JointRole::kHip, JointPlane::kCoronal);
    const int knee_g = body.find_group(JointRole::kKnee, JointPlane::kSagittal);
    int foot_g = -1;
    for (size_t g = 0; g < body.groups.size() && foot_g < 0; ++g) {
      const auto& grp = body.groups[g];
      if (grp.plane == JointPlane::kSagittal && grp.joints.size() == 2 &&
          body.joints[static_cast<size_t>(grp.joints[0])].body == body.feet[0])
        foot_g = static_cast<int>(g);
    }
    ASSERT_GE(foot_g, 0) << task;
    for (int side = 0; side < 2; ++side) {
      const CharacterJoint& hip = body.joints[static_cast<size_t>(body.groups[static_cast<size_t>(hip_g)].joints[static_cast<size_t>(side)])];
      const CharacterJoint& roll = body.joints[static_cast<size_t>(body.groups[static_cast<size_t>(roll_g)].joints[static_cast<size_t>(side)])];
      const CharacterJoint& knee = body.joints[static_cast<size_t>(body.groups[static_cast<size_t>(knee_g)].joints[static_cast<size_t>(side)])];
      const CharacterJoint& foot = body.joints[static_cast<size_t>(body.groups[static_cast<size_t>(foot_g)].joints[static_cast<size_t>(side)])];
      for (double bend : {0.2, 0.6}) {
        // The leg at the hip's reference angles with the knee bent further.
        mju_copy(d->qpos, m->qpos0, m->nq);
        d->qpos[knee.qpos] += (knee.upper > 0 ? 1 : -1) * bend;
        mj_kinematics(m, d);
        auto leg = [&]() {
          std::array<double, 3> v{};
          for (int i = 0; i < 3; ++i) v[static_cast<size_t>(i)] = d->xanchor[3 * foot.joint + i] - d->xanchor[3 * hip.joint + i];
          const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
          for (double& x : v) x /= n;
          return v;
        };
        const auto u = leg();
        std::array<double, 3> ap{}, ar{};
        for (int i = 0; i < 3; ++i) {
          ap[static_cast<size_t>(i)] = d->xaxis[3 * hip.joint + i];
          ar[static_cast<size_t>(i)] = d->xaxis[3 * roll.joint + i];
        }
        for (const std::array<double, 3> goal : {std::array<double, 3>{0.3, 0.1, -1}, {-0.4, -0.15, -1}, {0.0, 0.2, -1}}) {
          std::array<double, 3> w = goal;
          const double n = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
          for (double& x : w) x /= n;
          const HipAngles a = hip_angles_for(u, ap, ar, true, w);
          d->qpos[hip.qpos] = m->qpos0[hip.qpos] + a.pitch;
          d->qpos[roll.qpos] = m->qpos0[roll.qpos] + a.roll;
          mj_kinematics(m, d);
          const auto got = leg();
          for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(got[static_cast<size_t>(i)], w[static_cast<size_t>(i)], 1e-9)
                << task << " side " << side << " bend " << bend;
          }
          d->qpos[hip.qpos] = m->qpos0[hip.qpos];
          d->qpos[roll.qpos] = m->qpos0[roll.qpos];
        }
      }
    }
    mj_deleteData(d);
  }
}

// A hand-authored start jump of each character (the seed of its input motion) goes through
// the six phases in order and leaves the ground; every torque stays within its joint's net
// limit and nothing acts on the root, on the plain model replaying the recorded inputs.
TEST(Jump3dController, HandAuthoredJumpsTakeOffWithinTheLimits) {
  for (const char* task : {"jump_backwards", "robot_jump"}) {
    const Task t = load_task(test_files::jump3d_variant(task).string());
    const TaskEvaluator ev(t);
    const ParameterSet p = ev.load_parameters(t.seed.base);
    auto worker = ev.make_worker();
    StepRecorder record;
    EvaluationOptions options;
    options.recorder = &record;
    const Evaluation e = ev.evaluate(p.values(), *worker, options);
    EXPECT_FALSE(e.failed) << task << ": " << e.failure;
    EXPECT_TRUE(e.summary.took_off) << task;
    ASSERT_TRUE(e.has_flight()) << task;
    for (size_t k = 1; k < e.phases.begin.size(); ++k) {
      EXPECT_GT(e.phases.begin[k], e.phases.begin[k - 1]) << task << " phase " << k;
    }
    EXPECT_GT(e.phases.peak() - e.phases.takeoff(), 0.05) << task << ": a real flight";
    EXPECT_GT(e.summary.peak_com_z, 0.0);
    mjModel* plain = mj_copyModel(nullptr, ev.model().get());
    const NetTorqueCheck check = check_net_torque(plain, record, driven_joints(plain));
    mj_deleteModel(plain);
    EXPECT_EQ(check.steps, record.steps());
    EXPECT_LE(check.worst_excess, 0.0) << task;
    EXPECT_FALSE(check.blew_up);
    // No actuator drives a root joint.
    const mjModel* m = ev.model().get();
    for (int a = 0; a < m->nu; ++a) EXPECT_NE(m->jnt_bodyid[m->actuator_trnid[2 * a]], ev.body().root_body);
  }
}

// A push-off does not amplify a small change of the parameters: each 3D character's input
// motion and the same with every normalized parameter moved by at most 1e-6 stay within
// 1e-3 (m or rad, every coordinate of the pose) of each other from the start to the
// touch-down, and both take off and touch down on the same step. (Its legs once shared the
// push by a centre of pressure ten times as far from the COM as in balance: the human's two
// rollouts parted by 0.10 within 20 ms of take-off, the bird's by 0.04 over its push.)
TEST(Jump3dController, APushOffKeepsNearbyParametersNearby) {
  for (const char* task : {"jump_backwards", "robot_jump"}) {
    const Task t = load_task(test_files::jump3d_variant(task).string());
    const TaskEvaluator ev(t);
    const Eigen::VectorXd x = ev.load_parameters(t.m0).normalized();
    Eigen::VectorXd y = x;
    // Each coordinate 0.5e-6 or 1e-6 towards the middle of its range (some sit on a bound).
    for (int i = 0; i < y.size(); ++i) y[i] += (y[i] > 0.5 ? -1e-6 : 1e-6) * (i % 3 ? 1 : 0.5);
    auto worker = ev.make_worker();
    StepRecorder a, b;
    EvaluationOptions options;
    options.recorder = &a;
    const Evaluation ea = ev.evaluate_normalized(x, *worker, options);
    options.recorder = &b;
    const Evaluation eb = ev.evaluate_normalized(y, *worker, options);
    ASSERT_TRUE(ea.has_flight()) << task;
    ASSERT_TRUE(eb.has_flight()) << task;
    EXPECT_NEAR(ea.phases.takeoff(), eb.phases.takeoff(), 1e-9) << task;
    EXPECT_NEAR(ea.phases.landing(), eb.phases.landing(), 1e-9) << task;
    const int landing_step = static_cast<int>(std::lround(ea.phases.landing() / a.timestep));
    double worst = 0;
    for (int s = 0; s < std::min({a.steps(), b.steps(), landing_step}); ++s) {
      for (int i = 0; i < a.nq; ++i) {
        const size_t k = static_cast<size_t>(s) * static_cast<size_t>(a.nq) + static_cast<size_t>(i);
        worst = std::max(worst, std::fabs(a.qpos[k] - b.qpos[k]));
      }
    }
    EXPECT_LT(worst, 1e-3) << task;
  }
}

}  // namespace
// Controllers of different characters built one after another on one thread (a worker
// that evaluates both) give the same rollouts as on a thread of their own: the stance
// controller's scratch data follows the model it serves.
TEST(Jump3dRollouts, TheSameOnAThreadThatServedAnotherCharacter) {
  const TaskEvaluator human(load_task(test_files::jump3d_variant("jump_backwards").string()));
  const TaskEvaluator robot(load_task(test_files::jump3d_variant("robot_jump").string()));
  const ParameterSet h = human.load_parameters(human.task().m0);
  const ParameterSet r = robot.load_parameters(robot.task().m0);
  auto run = [](const TaskEvaluator& ev, const ParameterSet& p) {
    auto worker = ev.make_worker();
    return ev.evaluate_normalized(p.normalized(), *worker, EvaluationOptions{});
  };
  Evaluation alone_h, alone_r;
  std::thread([&] { alone_h = run(human, h); }).join();
  std::thread([&] { alone_r = run(robot, r); }).join();
  const Evaluation h1 = run(human, h), r1 = run(robot, r), h2 = run(human, h);
  for (const Evaluation* e : {&h1, &h2}) {
    EXPECT_EQ(e->constraint, alone_h.constraint);
    EXPECT_EQ(e->summary.touchdown_feet_x, alone_h.summary.touchdown_feet_x);
    EXPECT_EQ(e->summary.peak_com_z, alone_h.summary.peak_com_z);
  }
  EXPECT_EQ(r1.constraint, alone_r.constraint);
  EXPECT_EQ(r1.summary.touchdown_feet_x, alone_r.summary.touchdown_feet_x);
  EXPECT_EQ(alone_h.constraint, 0.0);
  EXPECT_EQ(alone_r.constraint, 0.0);
}

}  // namespace diverse
