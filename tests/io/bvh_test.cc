// BVH export: the file round-trips through our parser, and the forward kinematics of the
// written file reproduces MuJoCo's body positions and orientations (BVH axes), for the
// planar human (including a full backflip turn of the root) and a 3D model with free and
// ball joints; malformed files give one-line errors naming the line.
#include "io/bvh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>

#include "core/error.h"
#include "physics/model.h"
#include "support/stance_run.h"
#include "support/scratch.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

constexpr double kPi = std::numbers::pi;

std::shared_ptr<const SharedModel> human() {
  return SharedModel::from_file(std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.xml");
}

// A 3D character: free root, a ball joint, a hinge about a tilted axis, a rotated body frame.
constexpr const char* kHuman3d = R"(
<mujoco>
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <body name="torso" pos="0 0 1">
      <freejoint/>
      <geom type="capsule" fromto="0 0 0 0 0 0.4" size="0.1"/>
      <body name="upper arm" pos="0 0.2 0.35" quat="0.9238795 0 0.3826834 0">
        <joint name="shoulder" type="ball"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.04"/>
        <body name="forearm" pos="0 0 -0.3">
          <joint name="elbow" type="hinge" axis="0.3 1 0.2"/>
          <geom type="capsule" fromto="0 0 0 0 0 -0.25" size="0.035"/>
        </body>
      </body>
      <body name="thigh" pos="0 -0.1 0">
        <joint name="hip" type="ball"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.06"/>
      </body>
    </body>
  </worldbody>
</mujoco>)";

// Checks every BVH joint against its MuJoCo body at every frame: position within `tol` m
// and rotation matrix within 1e-5, after mapping MuJoCo axes to BVH axes.
void expect_matches_mujoco(const mjModel* m, const std::vector<std::vector<double>>& frames,
                           const Bvh& bvh, const std::vector<int>& bodies, double tol) {
  std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m), mj_deleteData);
  // C maps MuJoCo to BVH axes: (x, y, z) -> (x, z, -y).
  const double c[9] = {1, 0, 0, 0, 0, 1, 0, -1, 0};
  for (int f = 0; f < bvh.frame_count(); ++f) {
    std::copy(frames[static_cast<std::size_t>(f)].begin(), frames[static_cast<std::size_t>(f)].end(), d->qpos);
    mj_kinematics(m, d.get());
    const BvhPose pose = bvh_pose(bvh, f);
    for (std::size_t j = 0; j < bvh.joints.size(); ++j) {
      const int b = bodies[j];
      const auto expected = mujoco_to_bvh(d->xpos + 3 * b);
      for (int i = 0; i < 3; ++i)
        ASSERT_NEAR(pose.position[j][static_cast<std::size_t>(i)], expected[static_cast<std::size_t>(i)], tol)
            << bvh.joints[j].name << " frame " << f;
      // C R C^T
      double r[9], cr[9];
      mju_quat2Mat(r, d->xquat + 4 * b);
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) {
          cr[3 * i + k] = 0;
          for (int l = 0; l < 3; ++l) cr[3 * i + k] += c[3 * i + l] * r[3 * l + k];
        }
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) {
          double e = 0;
          for (int l = 0; l < 3; ++l) e += cr[3 * i + l] * c[3 * k + l];
          ASSERT_NEAR(pose.rotation[j][static_cast<std::size_t>(3 * i + k)], e, 1e-5)
              << bvh.joints[j].name << " frame " << f;
        }
    }
  }
}

// A backflip-like sequence of planar poses: the root turns a full 2 pi backwards while
// every joint swings through part of its range.
std::vector<std::vector<double>> planar_frames(const mjModel* m, int count) {
  std::vector<std::vector<double>> frames;
  for (int f = 0; f < count; ++f) {
    const double s = static_cast<double>(f) / (count - 1);
    std::vector<double> q(m->qpos0, m->qpos0 + m->nq);
    q[0] = 1.2 * s;                       // rootx
    q[1] = 0.6 * std::sin(kPi * s);       // rootz
    q[2] = 2 * kPi * s;                   // root pitch
    for (int j = 3; j < m->njnt; ++j) {   // hinges, within their ranges
      const double lo = m->jnt_range[2 * j], hi = m->jnt_range[2 * j + 1];
      q[static_cast<std::size_t>(m->jnt_qposadr[j])] = lo + (hi - lo) * (0.5 + 0.45 * std::sin(3 * s + j));
    }
    frames.push_back(q);
  }
  return frames;
}

TEST(BvhExport, PlanarHumanRoundTripsAndMatchesMujoco) {
  const auto model = human();
  const mjModel* m = model->get();
  const auto frames = planar_frames(m, 61);
  std::vector<int> bodies;
  const Bvh bvh = bvh_from_model(m, frames, 30.0, &bodies);

  // One joint per body but the world; the pelvis is the root.
  ASSERT_EQ(static_cast<int>(bvh.joints.size()), m->nbody - 1);
  EXPECT_EQ(bvh.joints[0].name, "pelvis");
  EXPECT_EQ(bvh.joints[0].parent, -1);
  // The root: 3 positions and 3 angles; every other body turns on one hinge about -y, a
  // single Zrotation channel holding the hinge's angle.
  EXPECT_EQ(bvh.channel_count(), 6 + (m->nbody - 2));
  for (std::size_t j = 1; j < bvh.joints.size(); ++j)
    EXPECT_EQ(bvh.joints[j].channels, std::vector<std::string>{"Zrotation"}) << bvh.joints[j].name;
  EXPECT_EQ(bvh.frame_count(), 61);
  EXPECT_DOUBLE_EQ(bvh.frame_time, 1.0 / 30.0);
  // The knee's offset is the shin's body position (0, 0, -0.39) in BVH axes.
  const int shin = bvh.find("shin_l");
  ASSERT_GE(shin, 0);
  EXPECT_NEAR(bvh.joints[static_cast<std::size_t>(shin)].offset[1], -0.39, 1e-12);
  EXPECT_EQ(bvh.joints[static_cast<std::size_t>(bvh.find("head"))].has_end_site, true);

  // Written and parsed back: same skeleton, frames within the 6 printed decimals.
  const fs::path file = test_files::scratch_dir("bvh_test") / "human.bvh";
  write_bvh(file, bvh);
  const Bvh back = read_bvh(file);
  ASSERT_EQ(back.joints.size(), bvh.joints.size());
  ASSERT_EQ(back.frame_count(), bvh.frame_count());
  EXPECT_NEAR(back.frame_time, bvh.frame_time, 1e-8);
  for (std::size_t j = 0; j < bvh.joints.size(); ++j) {
    EXPECT_EQ(back.joints[j].name, bvh.joints[j].name);
    EXPECT_EQ(back.joints[j].parent, bvh.joints[j].parent);
    EXPECT_EQ(back.joints[j].channels, bvh.joints[j].channels);
    EXPECT_EQ(back.joints[j].has_end_site, bvh.joints[j].has_end_site);
  }
  // Forward kinematics of the file we read back reproduces MuJoCo within 1 mm (in fact
  // within the rounding of the printed numbers).
  expect_matches_mujoco(m, frames, back, bodies, 1e-3);
  expect_matches_mujoco(m, frames, bvh, bodies, 1e-9);

  // Hinges about MuJoCo's -y are rotations about BVH +Z alone; the root's angle is
  // unwrapped, so a full turn ends at 360 degrees rather than jumping back to 0.
  const int root_z = 3;  // channels: X Y Z position, then Z X Y rotation
  double largest_step = 0;
  for (int f = 1; f < bvh.frame_count(); ++f)
    largest_step = std::max(largest_step, std::abs(bvh.frames[static_cast<std::size_t>(f)][root_z] -
                                                   bvh.frames[static_cast<std::size_t>(f - 1)][root_z]));
  EXPECT_LT(largest_step, 10.0);
  EXPECT_NEAR(bvh.frames.back()[root_z], 360.0, 1e-6);
  const int knee = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "knee_l")];
  const std::size_t knee_channel = 6 + static_cast<std::size_t>(shin - 1);
  for (std::size_t f = 0; f < bvh.frames.size(); ++f) {
    const auto& values = bvh.frames[f];
    EXPECT_NEAR(values[4], 0.0, 1e-9);  // root Xrotation
    EXPECT_NEAR(values[5], 0.0, 1e-9);  // root Yrotation
    EXPECT_NEAR(values[knee_channel], frames[f][static_cast<std::size_t>(knee)] * 180 / kPi, 1e-9);
  }
}

TEST(BvhExport, ThreeDimensionalModelMatchesMujoco) {
  const auto model = SharedModel::from_xml(kHuman3d, "human3d");
  const mjModel* m = model->get();
  std::vector<std::vector<double>> frames;
  for (int f = 0; f < 20; ++f) {
    const double s = 0.3 * f;
    std::vector<double> q(m->qpos0, m->qpos0 + m->nq);
    q[0] = 0.1 * f;
    q[1] = -0.05 * f;
    q[2] = 1.0 + 0.1 * std::sin(s);
    // Free root and the two ball joints: arbitrary unit quaternions.
    for (int adr : {3, 7, 12}) {
      double quat[4] = {std::cos(s + adr), std::sin(0.7 * s + adr), std::cos(1.3 * s), std::sin(2.1 * s - adr)};
      mju_normalize4(quat);
      std::copy(quat, quat + 4, q.begin() + adr);
    }
    q[11] = 1.5 * std::sin(s);  // elbow
    frames.push_back(q);
  }
  std::vector<int> bodies;
  const Bvh bvh = bvh_from_model(m, frames, 60.0, &bodies);
  ASSERT_EQ(bvh.joints.size(), 4u);
  EXPECT_EQ(bvh.joints[1].name, "upper_arm");  // one token
  const Bvh back = parse_bvh(bvh_text(bvh), "human3d.bvh");
  EXPECT_EQ(back.frame_count(), 20);
  expect_matches_mujoco(m, frames, back, bodies, 1e-3);
}

// qpos every `every` steps of a recorded rollout, from the initial state on.
std::vector<std::vector<double>> recorded_frames(const StepRecorder& r, int every) {
  std::vector<std::vector<double>> frames{r.qpos0};
  for (int k = every - 1; k < r.steps(); k += every)
    frames.emplace_back(r.qpos.begin() + static_cast<long>(k) * r.nq,
                        r.qpos.begin() + static_cast<long>(k + 1) * r.nq);
  return frames;
}

// The 3D human pushed forward and to its left, 1.5 s of stance control: its universal
// joints (pitch then roll) are two channels holding the two hinge angles, its hinges one,
// and the file's forward kinematics puts every body where MuJoCo does, in every frame.
TEST(BvhExport, Human3dUniversalJointsAreTwoHingeChannelsAndMatchMujoco) {
  const auto motion = test_support::stance_motion("human3d", {0.3, 0.3, 0.0}, 1.5);
  const mjModel* m = motion.model->get();
  const auto frames = recorded_frames(motion.record, 17);  // every 34 ms
  std::vector<int> bodies;
  const Bvh bvh = bvh_from_model(m, frames, 30.0, &bodies);
  ASSERT_EQ(static_cast<int>(bvh.joints.size()), m->nbody - 1);
  EXPECT_EQ(bvh.joints[0].channels, (std::vector<std::string>{"Xposition", "Yposition", "Zposition",
                                                              "Zrotation", "Xrotation", "Yrotation"}));
  const std::vector<std::string> universal{"Zrotation", "Xrotation"};
  const std::vector<std::string> hinge{"Zrotation"};
  for (const char* name : {"thigh_l", "thigh_r", "foot_l", "foot_r", "torso", "head", "upperarm_l",
                           "upperarm_r", "hand_l", "hand_r"})
    EXPECT_EQ(bvh.joints[static_cast<std::size_t>(bvh.find(name))].channels, universal) << name;
  for (const char* name : {"shin_l", "shin_r", "forearm_l", "forearm_r"})
    EXPECT_EQ(bvh.joints[static_cast<std::size_t>(bvh.find(name))].channels, hinge) << name;
  // 6 root channels, 10 universal joints, 4 hinges: the 24 internal degrees of freedom.
  EXPECT_EQ(bvh.channel_count(), 6 + 24);

  // The channel values are the hinge angles in degrees; the right roll turns about -x,
  // so its channel holds minus its angle. The push moves them.
  auto channel = [&](const char* body, int k) {
    std::size_t v = 0;
    for (int j = 0; j < bvh.find(body); ++j) v += bvh.joints[static_cast<std::size_t>(j)].channels.size();
    return v + static_cast<std::size_t>(k);
  };
  const int pitch_l = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "hip_pitch_l")];
  const int roll_r = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "hip_roll_r")];
  double roll_range = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    EXPECT_NEAR(bvh.frames[f][channel("thigh_l", 0)], frames[f][static_cast<std::size_t>(pitch_l)] * 180 / kPi, 1e-9);
    EXPECT_NEAR(bvh.frames[f][channel("thigh_r", 1)], -frames[f][static_cast<std::size_t>(roll_r)] * 180 / kPi, 1e-9);
    roll_range = std::max(roll_range, std::abs(frames[f][static_cast<std::size_t>(roll_r)] - frames[0][static_cast<std::size_t>(roll_r)]));
  }
  EXPECT_GT(roll_range * 180 / kPi, 0.5) << "the sideways push turns the hip roll";

  const Bvh back = parse_bvh(bvh_text(bvh), "human3d.bvh");
  expect_matches_mujoco(m, frames, bvh, bodies, 1e-9);
  expect_matches_mujoco(m, frames, back, bodies, 1e-4);
}

// The bird robot's hinges have reference angles (ref: qpos0 is not 0, and MuJoCo turns a
// hinge by qpos - qpos0): its channels hold the angle from the reference, and the file
// reproduces MuJoCo's poses.
TEST(BvhExport, BirdRobotHingesWithReferenceAnglesMatchMujoco) {
  const auto motion = test_support::stance_motion("robot3d", {-0.3, 0.2, 0.0}, 1.0);
  const mjModel* m = motion.model->get();
  const auto frames = recorded_frames(motion.record, 17);
  std::vector<int> bodies;
  const Bvh bvh = bvh_from_model(m, frames, 30.0, &bodies);
  EXPECT_EQ(bvh.joints[static_cast<std::size_t>(bvh.find("thigh_l"))].channels,
            (std::vector<std::string>{"Zrotation", "Xrotation"}));
  EXPECT_EQ(bvh.joints[static_cast<std::size_t>(bvh.find("shank_l"))].channels,
            std::vector<std::string>{"Zrotation"});
  const int knee = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "knee_l")];
  EXPECT_NEAR(m->qpos0[knee], 1.0, 1e-12);
  expect_matches_mujoco(m, frames, bvh, bodies, 1e-9);
  expect_matches_mujoco(m, frames, parse_bvh(bvh_text(bvh), "robot3d.bvh"), bodies, 1e-4);
}

TEST(BvhExport, ModelWithTwoMovingTreesIsAUserError) {
  const auto model = SharedModel::from_xml(R"(
<mujoco><worldbody>
  <body name="a"><freejoint/><geom size="0.1"/></body>
  <body name="b"><freejoint/><geom size="0.1"/></body>
</worldbody></mujoco>)", "two");
  const std::vector<std::vector<double>> frames{std::vector<double>(model->get()->qpos0, model->get()->qpos0 + 14)};
  try {
    bvh_from_model(model->get(), frames, 30.0);
    FAIL();
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(),
                 "BVH export: the model has more than one moving body tree (a, b); a BVH file has a single root");
  }
}

std::string parse_error(const std::string& text) {
  try {
    parse_bvh(text, "x.bvh");
  } catch (const UserError& e) {
    return e.what();
  }
  return "no error";
}

TEST(BvhParse, MalformedFilesNameTheLine) {
  const std::string head =
      "HIERARCHY\nROOT hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
      "  End Site\n  {\n    OFFSET 0 0.1 0\n  }\n}\nMOTION\n";
  EXPECT_EQ(parse_bvh(head + "Frames: 1\nFrame Time: 0.033333\n1 2 3 4 5 6\n", "x.bvh").frames[0][5], 6.0);
  EXPECT_EQ(parse_error("HIERARCHY\nROOT hips\nOFFSET 0 0 0\n"),
            "x.bvh: line 3: expected \"{\", found \"OFFSET\"");
  EXPECT_EQ(parse_error(head + "Frames: 1\nFrame Time: 0.033333\n1 2 3 4 5\n"),
            "x.bvh: line 14: expected 6 channel values, found 5");
  EXPECT_EQ(parse_error(head + "Frames: 2\nFrame Time: 0.033333\n1 2 3 4 5 6\n"),
            "x.bvh: line 14: expected 2 frames (as declared), found 1");
  EXPECT_EQ(parse_error(head + "Frames: 1\nFrame Time: 0.033333\n1 2 3 4 5 six\n"),
            "x.bvh: line 14: expected a channel value, found \"six\"");
  EXPECT_EQ(parse_error(head + "Frames: 1\nFrame Time: 0\n1 2 3 4 5 6\n"),
            "x.bvh: line 13: expected a frame time > 0");
  EXPECT_EQ(parse_error("HIERARCHY\nROOT hips\n{\n OFFSET 0 0 0\n CHANNELS 1 Wrotation\n}\n"),
            "x.bvh: line 5: expected a channel name (Xposition ... Zrotation), found \"Wrotation\"");
  EXPECT_EQ(parse_error("HIERARCHY\nROOT hips\n{\n OFFSET 0 0\n"),
            "x.bvh: line 4: expected an OFFSET value (file ends early)");
}

}  // namespace
}  // namespace diverse
