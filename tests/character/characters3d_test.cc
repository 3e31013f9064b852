// The 3D characters (assets/characters/human3d.*, robot3d.*): what the paper's section 5
// says of them (links, internal degrees of freedom, mass, height), torque limits as
// MuJoCo motors, a standing pose with flat feet at qpos0, left/right pairs that are
// mirror images, and a character file that covers every joint once.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <toml++/toml.h>

#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "character/character.h"
#include "physics/model.h"

namespace {

struct Expect {
  const char* name;
  int links;
  int internal_dof;
  double mass;    // kg
  double height;  // m
  bool hands;
  bool bird_knee;  // the knee bends backwards (flexion > 0), the ankle forward of it
};

const Expect kHuman{"human3d", 15, 24, 80.0, 1.80, true, false};
const Expect kRobot{"robot3d", 10, 14, 70.0, 2.90, false, true};

std::string asset(const std::string& name, const char* ext) {
  return std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/" + name + ext;
}

struct Model {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  explicit Model(const std::string& path) {
    char err[1000] = "";
    m = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
    EXPECT_NE(m, nullptr) << path << ": " << err;
    if (m != nullptr) {
      d = mj_makeData(m);
      mj_forward(m, d);
    }
  }
  ~Model() {
    if (d != nullptr) mj_deleteData(d);
    if (m != nullptr) mj_deleteModel(m);
  }
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;
};

// The character file's groups: joint names, and for each its group's plane.
struct Groups {
  std::vector<std::vector<std::string>> joints;
  std::vector<std::string> planes, roles;
  std::vector<std::string> hands, feet;
  std::string root_body, root_joint;
};

Groups read_groups(const std::string& path) {
  Groups g;
  const toml::table t = toml::parse_file(path);
  g.root_body = t["root"]["body"].value_or(std::string());
  g.root_joint = t["root"]["joint"].value_or(std::string());
  EXPECT_EQ(t["root"]["kind"].value_or(std::string()), "free");
  for (const toml::node& n : *t["groups"].as_array()) {
    const toml::table& e = *n.as_table();
    std::vector<std::string> js;
    for (const toml::node& j : *e["joints"].as_array()) js.push_back(j.value_or(std::string()));
    g.joints.push_back(js);
    g.planes.push_back(e["plane"].value_or(std::string()));
    g.roles.push_back(e["role"].value_or(std::string()));
    EXPECT_TRUE(e["wja"].is_number() && e["kp"].is_number() && e["kd"].is_number());
    EXPECT_FALSE(e.contains("shape"));
  }
  if (const toml::array* a = t["hands"]["bodies"].as_array()) {
    for (const toml::node& j : *a) g.hands.push_back(j.value_or(std::string()));
  }
  for (const toml::node& j : *t["feet"]["bodies"].as_array())
    g.feet.push_back(j.value_or(std::string()));
  EXPECT_FALSE(t.contains("shape"));
  return g;
}

int joint_id(const mjModel* m, const std::string& name) {
  const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
  EXPECT_GE(j, 0) << name;
  return j;
}

class Characters3d : public ::testing::TestWithParam<Expect> {};

TEST_P(Characters3d, LinksDofMassAndHeightAreThePapers) {
  const Expect& e = GetParam();
  Model model(asset(e.name, ".xml"));
  ASSERT_NE(model.m, nullptr);
  const mjModel* m = model.m;
  ASSERT_EQ(m->jnt_type[0], mjJNT_FREE);
  const int root = m->jnt_bodyid[0];
  int links = 0;
  double mass = 0;
  for (int b = 1; b < m->nbody; ++b) {
    if (m->body_rootid[b] != root) continue;
    ++links;
    mass += m->body_mass[b];
    EXPECT_GT(m->body_mass[b], 0.1) << mj_id2name(m, mjOBJ_BODY, b);
  }
  EXPECT_EQ(links, e.links);
  EXPECT_EQ(m->nv - 6, e.internal_dof);
  EXPECT_EQ(m->njnt - 1, e.internal_dof);
  EXPECT_NEAR(mass, e.mass, 0.005 * e.mass);

  double low = INFINITY, high = -INFINITY;
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->body_rootid[m->geom_bodyid[g]] != root || m->geom_bodyid[g] == 0) continue;
    double lo = 0, hi = 0;
    diverse::geom_z_extent(m, model.d, g, &lo, &hi);
    low = std::min(low, lo);
    high = std::max(high, hi);
  }
  EXPECT_NEAR(low, 0.0, 0.001) << "the lowest foot point rests on the floor at qpos0";
  EXPECT_NEAR(high - low, e.height, 0.01);
  EXPECT_EQ(m->opt.integrator, mjINT_EULER);
  EXPECT_DOUBLE_EQ(m->opt.timestep, 0.002);
}

TEST_P(Characters3d, FeetAreBoxesFlatOnTheFloor) {
  const Expect& e = GetParam();
  Model model(asset(e.name, ".xml"));
  ASSERT_NE(model.m, nullptr);
  const mjModel* m = model.m;
  const Groups groups = read_groups(asset(e.name, ".toml"));
  ASSERT_EQ(groups.feet.size(), 2u);
  for (const std::string& foot : groups.feet) {
    const int b = mj_name2id(m, mjOBJ_BODY, foot.c_str());
    ASSERT_GE(b, 0) << foot;
    int boxes = 0;
    for (int g = 0; g < m->ngeom; ++g) {
      if (m->geom_bodyid[g] != b) continue;
      ASSERT_EQ(m->geom_type[g], mjGEOM_BOX) << foot;
      ++boxes;
      const double* R = model.d->geom_xmat + 9 * g;
      EXPECT_NEAR(R[8], 1.0, 1e-9) << foot << ": sole horizontal";
      double lo = 0, hi = 0;
      diverse::geom_z_extent(m, model.d, g, &lo, &hi);
      EXPECT_NEAR(lo, 0.0, 0.001) << foot;
      EXPECT_EQ(m->geom_condim[g], 3);
      EXPECT_GE(m->geom_friction[3 * g], 0.9);
      EXPECT_LE(m->geom_friction[3 * g], 1.0);
    }
    EXPECT_EQ(boxes, 1) << foot;
  }
  // No self-collision: body geoms collide only with the floor and scene objects.
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_bodyid[g] == 0) {
      EXPECT_EQ(m->geom_contype[g], 0);
      EXPECT_EQ(m->geom_conaffinity[g], 1);
    } else {
      EXPECT_EQ(m->geom_contype[g], 1);
      EXPECT_EQ(m->geom_conaffinity[g], 0);
    }
  }
}

TEST_P(Characters3d, EveryJointHasOneForceLimitedMotorAndTheRootNone) {
  const Expect& e = GetParam();
  Model model(asset(e.name, ".xml"));
  ASSERT_NE(model.m, nullptr);
  const mjModel* m = model.m;
  std::vector<int> motors(static_cast<size_t>(m->njnt), 0);
  for (int a = 0; a < m->nu; ++a) {
    ASSERT_EQ(m->actuator_trntype[a], mjTRN_JOINT);
    const int j = m->actuator_trnid[2 * a];
    ++motors[static_cast<size_t>(j)];
    EXPECT_EQ(m->actuator_gear[6 * a], 1.0);
    EXPECT_EQ(m->actuator_gaintype[a], mjGAIN_FIXED);
    EXPECT_EQ(m->actuator_biastype[a], mjBIAS_NONE);
    EXPECT_TRUE(m->actuator_forcelimited[a]);
    EXPECT_GT(m->actuator_forcerange[2 * a + 1], 0);
    EXPECT_EQ(m->actuator_forcerange[2 * a], -m->actuator_forcerange[2 * a + 1]);
  }
  for (int j = 0; j < m->njnt; ++j) {
    if (m->jnt_type[j] == mjJNT_FREE) {
      EXPECT_EQ(motors[static_cast<size_t>(j)], 0) << "the root is unactuated";
      EXPECT_EQ(m->dof_damping[m->jnt_dofadr[j]], 0);
    } else {
      EXPECT_EQ(m->jnt_type[j], mjJNT_HINGE);
      EXPECT_EQ(motors[static_cast<size_t>(j)], 1) << mj_id2name(m, mjOBJ_JOINT, j);
      EXPECT_TRUE(m->jnt_limited[j]);
      EXPECT_GE(m->dof_armature[m->jnt_dofadr[j]], 0.01);
      EXPECT_LE(m->dof_armature[m->jnt_dofadr[j]], 0.02);
    }
  }
}

TEST(Characters3d, HumanTorqueLimitsAreThePapers) {
  Model model(asset("human3d", ".xml"));
  ASSERT_NE(model.m, nullptr);
  const mjModel* m = model.m;
  const std::map<std::string, double> limit{{"hip", 200},   {"waist", 200}, {"knee", 150},
                                            {"ankle", 150}, {"neck", 50},   {"shoulder", 100},
                                            {"elbow", 100}, {"wrist", 100}};
  for (int a = 0; a < m->nu; ++a) {
    const std::string joint = mj_id2name(m, mjOBJ_JOINT, m->actuator_trnid[2 * a]);
    const std::string kind = joint.substr(0, joint.find('_'));
    ASSERT_TRUE(limit.count(kind)) << joint;
    EXPECT_EQ(m->actuator_forcerange[2 * a + 1], limit.at(kind)) << joint;
  }
}

TEST_P(Characters3d, CharacterFileCoversEveryJointOnceAndPairsMatch) {
  const Expect& e = GetParam();
  Model model(asset(e.name, ".xml"));
  ASSERT_NE(model.m, nullptr);
  const mjModel* m = model.m;
  const Groups g = read_groups(asset(e.name, ".toml"));
  EXPECT_EQ(g.root_joint, mj_id2name(m, mjOBJ_JOINT, 0));
  EXPECT_EQ(g.root_body, mj_id2name(m, mjOBJ_BODY, m->jnt_bodyid[0]));
  EXPECT_EQ(g.hands.size(), e.hands ? 2u : 0u);
  std::multiset<std::string> listed;
  for (size_t i = 0; i < g.joints.size(); ++i) {
    const auto& js = g.joints[i];
    ASSERT_TRUE(js.size() == 1 || js.size() == 2);
    for (const std::string& j : js) listed.insert(j);
    const int a = joint_id(m, js[0]);
    const double* axis_a = m->jnt_axis + 3 * a;
    if (g.planes[i] == "sagittal") {
      EXPECT_NEAR(axis_a[1], -1.0, 1e-12) << js[0] << " turns about -y";
    } else if (g.planes[i] == "coronal") {
      EXPECT_NEAR(std::fabs(axis_a[0]), 1.0, 1e-12) << js[0] << " turns about x";
    }
    if (js.size() == 2) {
      const int b = joint_id(m, js[1]);
      EXPECT_EQ(m->jnt_range[2 * a], m->jnt_range[2 * b]) << js[0];
      EXPECT_EQ(m->jnt_range[2 * a + 1], m->jnt_range[2 * b + 1]) << js[0];
      EXPECT_EQ(m->qpos0[m->jnt_qposadr[a]], m->qpos0[m->jnt_qposadr[b]]) << js[0];
      // Mirrored: the right axis is the left axis reflected in the x-z plane, as a pseudo
      // vector (x and z components flip sign, y stays).
      const double* axis_b = m->jnt_axis + 3 * b;
      EXPECT_NEAR(axis_b[0], -axis_a[0], 1e-12) << js[0];
      EXPECT_NEAR(axis_b[1], axis_a[1], 1e-12) << js[0];
      EXPECT_NEAR(axis_b[2], -axis_a[2], 1e-12) << js[0];
    }
  }
  for (int j = 1; j < m->njnt; ++j) {
    EXPECT_EQ(listed.count(mj_id2name(m, mjOBJ_JOINT, j)), 1u) << mj_id2name(m, mjOBJ_JOINT, j);
  }
  EXPECT_EQ(listed.size(), static_cast<size_t>(m->njnt - 1));
}

// Equal angles on a left/right pair give mirror-image poses: with every pair at the same
// (arbitrary, in-range) angles and the centre joints at 0, each left body is its right
// twin reflected in the x-z plane through the root.
TEST_P(Characters3d, EqualAnglesOnAPairAreMirrorImages) {
  const Expect& e = GetParam();
  Model model(asset(e.name, ".xml"));
  ASSERT_NE(model.m, nullptr);
  const mjModel* m = model.m;
  mjData* d = model.d;
  const Groups g = read_groups(asset(e.name, ".toml"));
  mju_copy(d->qpos, m->qpos0, m->nq);
  int k = 0;
  for (const auto& js : g.joints) {
    if (js.size() != 2) continue;
    const int a = joint_id(m, js[0]), b = joint_id(m, js[1]);
    const double lo = m->jnt_range[2 * a], hi = m->jnt_range[2 * a + 1];
    const double q = lo + (hi - lo) * (0.2 + 0.07 * (k++ % 9));
    d->qpos[m->jnt_qposadr[a]] = q;
    d->qpos[m->jnt_qposadr[b]] = q;
  }
  mj_kinematics(m, d);
  int pairs = 0;
  for (int b = 1; b < m->nbody; ++b) {
    std::string name = mj_id2name(m, mjOBJ_BODY, b);
    if (name.size() < 2 || name.substr(name.size() - 2) != "_l") continue;
    const int r = mj_name2id(m, mjOBJ_BODY, (name.substr(0, name.size() - 2) + "_r").c_str());
    ASSERT_GE(r, 0) << name;
    ++pairs;
    EXPECT_NEAR(d->xipos[3 * b], d->xipos[3 * r], 1e-9) << name;
    EXPECT_NEAR(d->xipos[3 * b + 1], -d->xipos[3 * r + 1], 1e-9) << name;
    EXPECT_NEAR(d->xipos[3 * b + 2], d->xipos[3 * r + 2], 1e-9) << name;
    EXPECT_GT(d->xipos[3 * b + 1], 0) << name << " is on the left (+y)";
    EXPECT_EQ(m->body_mass[b], m->body_mass[r]) << name;
  }
  EXPECT_GT(pairs, 0);
}

// Sign conventions shared with human2d: hip flexion moves the knee forward; positive
// coronal angles move the limb outward.
TEST_P(Characters3d, FlexionAndAbductionSigns) {
  const Expect& e = GetParam();
  Model model(asset(e.name, ".xml"));
  ASSERT_NE(model.m, nullptr);
  const mjModel* m = model.m;
  mjData* d = model.d;
  const int thigh = mj_name2id(m, mjOBJ_BODY, "thigh_l");
  ASSERT_GE(thigh, 0);
  const int hip = joint_id(m, "hip_pitch_l"), roll = joint_id(m, "hip_roll_l");
  // The thigh's centre of mass sits below the hip; flexing moves it forward (+x), abducting
  // the left thigh moves it to the left (+y).
  mju_copy(d->qpos, m->qpos0, m->nq);
  mj_kinematics(m, d);
  const double x0 = d->xipos[3 * thigh], y0 = d->xipos[3 * thigh + 1];
  d->qpos[m->jnt_qposadr[hip]] += 0.3;
  mj_kinematics(m, d);
  EXPECT_GT(d->xipos[3 * thigh], x0 + 0.01);
  mju_copy(d->qpos, m->qpos0, m->nq);
  d->qpos[m->jnt_qposadr[roll]] += 0.3;
  mj_kinematics(m, d);
  EXPECT_GT(d->xipos[3 * thigh + 1], y0 + 0.01);

  // Knee: a human flexes it below 0 (the shin swings back); the bird robot bends it
  // backwards, above 0, with the ankle forward of the knee in its stance.
  const int knee = joint_id(m, "knee_l");
  const int shin = m->jnt_bodyid[knee];
  const int ankle_body = m->body_parentid[mj_name2id(m, mjOBJ_BODY, "foot_l")] == shin
                             ? mj_name2id(m, mjOBJ_BODY, "foot_l")
                             : mj_name2id(m, mjOBJ_BODY, "tarsus_l");
  mju_copy(d->qpos, m->qpos0, m->nq);
  mj_kinematics(m, d);
  const double knee_x = d->xpos[3 * shin], ankle_x = d->xpos[3 * ankle_body];
  if (!e.bird_knee) {
    EXPECT_EQ(m->jnt_range[2 * knee + 1], 0.0);
    EXPECT_LT(m->jnt_range[2 * knee], -2.0);
  } else {
    EXPECT_GE(m->jnt_range[2 * knee], 0.0);
    EXPECT_GT(m->jnt_range[2 * knee + 1], 2.0);
    EXPECT_GT(ankle_x, knee_x + 0.1) << "the ankle is forward of the knee";
  }
  d->qpos[m->jnt_qposadr[knee]] += e.bird_knee ? 0.3 : -0.3;
  mj_kinematics(m, d);
  const double moved = d->xpos[3 * ankle_body] - ankle_x;
  if (!e.bird_knee) {
    EXPECT_LT(moved, -0.05) << "human knee flexion swings the ankle back";
  } else {
    EXPECT_GT(moved, 0.05) << "bird knee flexion swings the ankle forward";
  }
}

// Numerical stability of the model as built (Euler, 2 ms, armature): stiff PD on every
// joint toward qpos0, the damping part in dof_damping as the joint drives write it, holds
// the standing pose for 2 s without a MuJoCo warning, only the feet touching the floor.
TEST_P(Characters3d, StiffPdHoldsTheStandingPoseStably) {
  const Expect& e = GetParam();
  Model model(asset(e.name, ".xml"));
  ASSERT_NE(model.m, nullptr);
  mjModel* m = model.m;
  mjData* d = model.d;
  const double kp = 3000, kd = 200;
  for (int i = 6; i < m->nv; ++i) m->dof_damping[i] = kd;
  const Groups g = read_groups(asset(e.name, ".toml"));
  const int foot_l = mj_name2id(m, mjOBJ_BODY, g.feet[0].c_str());
  const int foot_r = mj_name2id(m, mjOBJ_BODY, g.feet[1].c_str());
  const double z0 = d->qpos[2];
  double max_speed = 0;
  for (int step = 0; step < 1000; ++step) {
    mj_step1(m, d);
    for (int a = 0; a < m->nu; ++a) {
      const int q = m->jnt_qposadr[m->actuator_trnid[2 * a]];
      d->ctrl[a] = kp * (m->qpos0[q] - d->qpos[q]);
    }
    mj_step2(m, d);
    for (int c = 0; c < d->ncon; ++c) {
      const int b1 = m->geom_bodyid[d->contact[c].geom1], b2 = m->geom_bodyid[d->contact[c].geom2];
      const int b = b1 == 0 ? b2 : b1;
      ASSERT_TRUE(b == foot_l || b == foot_r)
          << mj_id2name(m, mjOBJ_BODY, b) << " touches the floor";
    }
    for (int i = 0; i < m->nv; ++i) max_speed = std::max(max_speed, std::fabs(d->qvel[i]));
  }
  for (int w = 0; w < mjNWARNING; ++w) EXPECT_EQ(d->warning[w].number, 0) << w;
  EXPECT_LT(max_speed, 0.5);
  EXPECT_NEAR(d->qpos[2], z0, 0.02);
}

// The character file binds to its model through the project's own loader, which
// validates it (every joint in a group, pairs alike, one force-limited motor per joint).
TEST_P(Characters3d, BindsThroughTheCharacterFile) {
  const Expect& e = GetParam();
  auto spec = std::make_shared<diverse::CharacterSpec>(
      diverse::load_character_file(asset(e.name, ".toml")));
  EXPECT_EQ(spec->root, diverse::RootKind::kFree);
  EXPECT_FALSE(spec->has_shape());
  Model model(spec->model);
  ASSERT_NE(model.m, nullptr);
  const diverse::Character body = diverse::bind_character(spec, model.m, spec->model);
  EXPECT_EQ(body.dof(), e.internal_dof);
  EXPECT_EQ(static_cast<int>(body.links.size()), e.links);
  EXPECT_NEAR(body.total_mass, e.mass, 0.005 * e.mass);
  EXPECT_NEAR(body.height, e.height, 0.01);
  EXPECT_EQ(body.hands.size(), e.hands ? 2u : 0u);
  EXPECT_GE(body.find_group(diverse::JointRole::kHip, diverse::JointPlane::kSagittal), 0);
  EXPECT_GE(body.find_group(diverse::JointRole::kHip, diverse::JointPlane::kCoronal), 0);
  EXPECT_GE(body.find_group(diverse::JointRole::kKnee), 0);
  EXPECT_GE(body.find_group(diverse::JointRole::kAnkle), 0);
  for (const diverse::CharacterJoint& j : body.joints) {
    EXPECT_GT(j.torque_limit, 0) << j.name;
    EXPECT_GT(body.groups[static_cast<size_t>(j.group)].kp, 0) << j.name;
    EXPECT_GT(body.groups[static_cast<size_t>(j.group)].kd, 0) << j.name;
  }
}

INSTANTIATE_TEST_SUITE_P(Both, Characters3d, ::testing::Values(kHuman, kRobot),
                         [](const ::testing::TestParamInfo<Expect>& param_info) {
                           return std::string(param_info.param.name);
                         });

}  // namespace
