// glTF export: the file reads back with tinygltf; it has one node per body, nested as the
// bodies are, each with a mesh of its geoms in the model's colours (rigid) or one skinned
// mesh over them (the default: its skin's joint transforms, composed over the animation,
// put every bone and every vertex where MuJoCo puts them); and its animation,
// evaluated at every keyframe and composed down the node tree, puts every body where MuJoCo
// does (position and orientation, in glTF's Y-up axes), for the 3D human pushed sideways,
// the bird robot and the planar human. Several motions side by side keep their own bodies,
// and a shaped body (longer thighs) its own proportions.
#include "io/gltf.h"

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <cstring>
#include <filesystem>
#include <memory>
#include <unistd.h>

#include <Eigen/Geometry>

#include "core/error.h"
#include "character/character.h"
#include "character/shape.h"
#include "physics/model.h"
#include "support/stance_run.h"

namespace diverse {
namespace {
namespace fs = std::filesystem;

fs::path temp_dir() {
  const fs::path dir = fs::temp_directory_path() / ("diverse_gltf_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir;
}

tinygltf::Model read_glb(const fs::path& path) {
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool ok = loader.LoadBinaryFromFile(&model, &err, &warn, path.string());
  EXPECT_TRUE(ok) << err;
  EXPECT_TRUE(err.empty()) << err;
  return model;
}

// Floats of one accessor (tightly packed, as the exporter writes them).
std::vector<float> floats(const tinygltf::Model& m, int accessor) {
  const tinygltf::Accessor& a = m.accessors[static_cast<std::size_t>(accessor)];
  const tinygltf::BufferView& v = m.bufferViews[static_cast<std::size_t>(a.bufferView)];
  const int width = a.type == TINYGLTF_TYPE_SCALAR ? 1 : a.type == TINYGLTF_TYPE_VEC3 ? 3 : 4;
  std::vector<float> out(a.count * static_cast<std::size_t>(width));
  std::memcpy(out.data(), m.buffers[0].data.data() + v.byteOffset + a.byteOffset, out.size() * sizeof(float));
  return out;
}

std::vector<std::vector<double>> recorded_frames(const StepRecorder& r, int every) {
  std::vector<std::vector<double>> frames{r.qpos0};
  for (int k = every - 1; k < r.steps(); k += every)
    frames.emplace_back(r.qpos.begin() + static_cast<long>(k) * r.nq,
                        r.qpos.begin() + static_cast<long>(k + 1) * r.nq);
  return frames;
}

// World position (glTF axes) and rotation (w, x, y, z in glTF axes) of every node at
// keyframe k of the file's animation.
struct NodePose {
  std::vector<std::array<double, 3>> pos;
  std::vector<std::array<double, 4>> quat;
};
NodePose pose_at(const tinygltf::Model& g, std::size_t k) {
  const std::size_t n = g.nodes.size();
  std::vector<std::array<double, 3>> t(n, {0, 0, 0});
  std::vector<std::array<double, 4>> r(n, {1, 0, 0, 0});
  for (std::size_t i = 0; i < n; ++i) {
    const auto& node = g.nodes[i];
    if (node.translation.size() == 3) t[i] = {node.translation[0], node.translation[1], node.translation[2]};
    if (node.rotation.size() == 4) r[i] = {node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]};
  }
  for (const auto& c : g.animations.at(0).channels) {
    const auto& s = g.animations[0].samplers[static_cast<std::size_t>(c.sampler)];
    const std::vector<float> out = floats(g, s.output);
    const auto i = static_cast<std::size_t>(c.target_node);
    if (c.target_path == "translation") {
      t[i] = {out[3 * k], out[3 * k + 1], out[3 * k + 2]};
    } else {
      r[i] = {out[4 * k + 3], out[4 * k], out[4 * k + 1], out[4 * k + 2]};
    }
  }
  NodePose pose;
  pose.pos.resize(n);
  pose.quat.resize(n);
  std::vector<int> parent(n, -1);
  for (std::size_t i = 0; i < n; ++i)
    for (int c : g.nodes[i].children) parent[static_cast<std::size_t>(c)] = static_cast<int>(i);
  // Parents come before children in the exporter's node order.
  for (std::size_t i = 0; i < n; ++i) {
    if (parent[i] < 0) {
      pose.pos[i] = t[i];
      pose.quat[i] = r[i];
      continue;
    }
    const auto p = static_cast<std::size_t>(parent[i]);
    double moved[3], q[4];
    mju_rotVecQuat(moved, t[i].data(), pose.quat[p].data());
    mju_mulQuat(q, pose.quat[p].data(), r[i].data());
    pose.pos[i] = {pose.pos[p][0] + moved[0], pose.pos[p][1] + moved[1], pose.pos[p][2] + moved[2]};
    pose.quat[i] = {q[0], q[1], q[2], q[3]};
  }
  return pose;
}

// Every body node at every keyframe against MuJoCo: position within 1e-5 m, orientation
// within 1e-5 (float precision), in glTF axes (x, z, -y).
void expect_matches_mujoco(const mjModel* m, const std::vector<std::vector<double>>& frames,
                           const tinygltf::Model& g, const std::string& prefix) {
  std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m), mj_deleteData);
  std::vector<int> node_of(static_cast<std::size_t>(m->nbody), -1);
  for (int b = 1; b < m->nbody; ++b)
    for (std::size_t i = 0; i < g.nodes.size(); ++i)
      if (g.nodes[i].name == prefix + mj_id2name(m, mjOBJ_BODY, b)) node_of[static_cast<std::size_t>(b)] = static_cast<int>(i);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    std::copy(frames[k].begin(), frames[k].end(), d->qpos);
    mj_kinematics(m, d.get());
    const NodePose pose = pose_at(g, k);
    for (int b = 1; b < m->nbody; ++b) {
      const int i = node_of[static_cast<std::size_t>(b)];
      ASSERT_GE(i, 0) << mj_id2name(m, mjOBJ_BODY, b);
      const double* x = d->xpos + 3 * b;
      const std::array<double, 3> expected{x[0], x[2], -x[1]};
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(pose.pos[static_cast<std::size_t>(i)][static_cast<std::size_t>(c)], expected[static_cast<std::size_t>(c)], 1e-5)
            << mj_id2name(m, mjOBJ_BODY, b) << " frame " << k;
      const double* q = d->xquat + 4 * b;
      const std::array<double, 4> e{q[0], q[1], q[3], -q[2]};
      const auto& got = pose.quat[static_cast<std::size_t>(i)];
      const double dot = std::abs(e[0] * got[0] + e[1] * got[1] + e[2] * got[2] + e[3] * got[3]);
      ASSERT_NEAR(dot, 1.0, 1e-5) << mj_id2name(m, mjOBJ_BODY, b) << " frame " << k;
    }
  }
}

GltfOptions rigid() {
  GltfOptions o;
  o.skinned = false;
  return o;
}

// A node's world transform at keyframe k (glTF axes).
Eigen::Affine3d world_of(const NodePose& pose, int node) {
  const auto& p = pose.pos[static_cast<std::size_t>(node)];
  const auto& q = pose.quat[static_cast<std::size_t>(node)];
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  t.translate(Eigen::Vector3d(p[0], p[1], p[2]));
  t.rotate(Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized());
  return t;
}

Eigen::Vector3d to_gltf(const Eigen::Vector3d& v) { return {v[0], v[2], -v[1]}; }

// The skinned character: a skin over one joint per body, in body order, with the
// humanoid names on the 3D human's joints; composing each joint's world transform at
// every keyframe with its inverse bind matrix moves the bind pose's bones and vertices to
// where MuJoCo puts the bodies and their geoms, within 1 mm (float precision: 1e-5 m).
TEST(GltfSkin, Human3dSkinComposesToMujocoBodies) {
  const auto motion = test_support::stance_motion("human3d", {0.2, 0.3, 0.0}, 1.5);
  const mjModel* m = motion.model->get();
  const auto frames = recorded_frames(motion.record, 17);
  const fs::path file = temp_dir() / "skinned.glb";
  write_glb(file, {GltfMotion{m, frames, "M0", {0.5, 1.0, 0}}});
  const tinygltf::Model g = read_glb(file);
  ASSERT_EQ(g.skins.size(), 1u);
  const tinygltf::Skin& skin = g.skins[0];
  ASSERT_EQ(skin.joints.size(), static_cast<std::size_t>(m->nbody - 1));  // 15 bones
  for (int b = 1; b < m->nbody; ++b)
    EXPECT_EQ(g.nodes[static_cast<std::size_t>(skin.joints[static_cast<std::size_t>(b - 1)])].name,
              mj_id2name(m, mjOBJ_BODY, b));
  EXPECT_EQ(g.nodes[static_cast<std::size_t>(skin.skeleton)].name, "M0");
  // The humanoid names.
  std::map<std::string, std::string> humanoid;
  for (int j : skin.joints) {
    const auto& node = g.nodes[static_cast<std::size_t>(j)];
    EXPECT_LT(node.mesh, 0) << node.name;  // joints carry no meshes of their own
    if (node.extras.Has("humanoid_bone")) humanoid[node.name] = node.extras.Get("humanoid_bone").Get<std::string>();
  }
  EXPECT_EQ(humanoid.size(), 15u);
  EXPECT_EQ(humanoid["pelvis"], "Hips");
  EXPECT_EQ(humanoid["torso"], "Spine");
  EXPECT_EQ(humanoid["thigh_l"], "LeftUpperLeg");
  EXPECT_EQ(humanoid["forearm_r"], "RightLowerArm");
  // The skinned mesh: a root node of the scene, one primitive per visible geom, each vertex
  // on one joint with weight 1.
  int mesh_node = -1;
  for (int n : g.scenes[0].nodes)
    if (g.nodes[static_cast<std::size_t>(n)].skin == 0) mesh_node = n;
  ASSERT_GE(mesh_node, 0);
  const tinygltf::Node& skinned = g.nodes[static_cast<std::size_t>(mesh_node)];
  EXPECT_EQ(skinned.name, "M0 body");
  EXPECT_TRUE(skinned.translation.empty() && skinned.rotation.empty() && skinned.matrix.empty());
  const tinygltf::Mesh& mesh = g.meshes[static_cast<std::size_t>(skinned.mesh)];
  int geoms = 0;
  for (int gi = 0; gi < m->ngeom; ++gi) geoms += m->geom_bodyid[gi] > 0 && m->geom_group[gi] <= 2;
  EXPECT_EQ(mesh.primitives.size(), static_cast<std::size_t>(geoms));

  const tinygltf::Accessor& ibm_accessor = g.accessors[static_cast<std::size_t>(skin.inverseBindMatrices)];
  ASSERT_EQ(ibm_accessor.type, TINYGLTF_TYPE_MAT4);
  ASSERT_EQ(ibm_accessor.count, skin.joints.size());
  const tinygltf::BufferView& ibm_view = g.bufferViews[static_cast<std::size_t>(ibm_accessor.bufferView)];
  std::vector<float> ibm_floats(16 * skin.joints.size());
  std::memcpy(ibm_floats.data(), g.buffers[0].data.data() + ibm_view.byteOffset, ibm_floats.size() * sizeof(float));
  std::vector<Eigen::Matrix4d> ibm;
  for (std::size_t j = 0; j < skin.joints.size(); ++j)
    ibm.push_back(Eigen::Map<const Eigen::Matrix4f>(ibm_floats.data() + 16 * j).cast<double>());

  // Every primitive's vertices at the bind pose, with their joints.
  struct Vertex {
    Eigen::Vector3d bind;
    int joint;
  };
  std::vector<Vertex> vertices;
  for (const auto& prim : mesh.primitives) {
    const std::vector<float> pos = floats(g, prim.attributes.at("POSITION"));
    const std::vector<float> weights = floats(g, prim.attributes.at("WEIGHTS_0"));
    const tinygltf::Accessor& ja = g.accessors[static_cast<std::size_t>(prim.attributes.at("JOINTS_0"))];
    ASSERT_EQ(ja.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    const tinygltf::BufferView& jv = g.bufferViews[static_cast<std::size_t>(ja.bufferView)];
    std::vector<std::uint16_t> joints(4 * ja.count);
    std::memcpy(joints.data(), g.buffers[0].data.data() + jv.byteOffset, joints.size() * 2);
    ASSERT_EQ(joints.size() / 4, pos.size() / 3);
    for (std::size_t v = 0; v < ja.count; v += 7) {  // every 7th vertex
      ASSERT_EQ(weights[4 * v], 1.0f);
      ASSERT_EQ(weights[4 * v + 1] + weights[4 * v + 2] + weights[4 * v + 3], 0.0f);
      vertices.push_back({Eigen::Vector3d(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]), joints[4 * v]});
    }
  }
  ASSERT_GT(vertices.size(), 200u);

  // The bind pose: MuJoCo at the model's qpos0.
  std::unique_ptr<mjData, void (*)(mjData*)> bind(mj_makeData(m), mj_deleteData);
  mj_kinematics(m, bind.get());
  std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m), mj_deleteData);
  const Eigen::Vector3d offset(0.5, 0.0, -1.0);  // (0.5, 1, 0) in MuJoCo axes
  double worst_bone = 0, worst_vertex = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    std::copy(frames[k].begin(), frames[k].end(), d->qpos);
    mj_kinematics(m, d.get());
    const NodePose pose = pose_at(g, k);
    std::vector<Eigen::Matrix4d> skinning;  // joint world transform times inverse bind matrix
    for (std::size_t j = 0; j < skin.joints.size(); ++j)
      skinning.push_back(world_of(pose, skin.joints[j]).matrix() * ibm[j]);
    for (int b = 1; b < m->nbody; ++b) {
      const Eigen::Matrix4d& s = skinning[static_cast<std::size_t>(b - 1)];
      // The bone's origin at the bind pose, moved by its joint.
      const Eigen::Vector3d origin = to_gltf(Eigen::Map<const Eigen::Vector3d>(bind->xpos + 3 * b));
      const Eigen::Vector3d moved = (s * origin.homogeneous()).head<3>();
      const Eigen::Vector3d expected = to_gltf(Eigen::Map<const Eigen::Vector3d>(d->xpos + 3 * b)) + offset;
      worst_bone = std::max(worst_bone, (moved - expected).norm());
    }
    for (const Vertex& v : vertices) {
      const int b = v.joint + 1;
      // The vertex in its body's frame (MuJoCo axes), then where the body is at frame k.
      const Eigen::Vector3d bind_mj(v.bind[0], -v.bind[2], v.bind[1]);
      const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> r0(bind->xmat + 9 * b), rk(d->xmat + 9 * b);
      const Eigen::Vector3d local = r0.transpose() * (bind_mj - Eigen::Map<const Eigen::Vector3d>(bind->xpos + 3 * b));
      const Eigen::Vector3d expected = to_gltf(rk * local + Eigen::Map<const Eigen::Vector3d>(d->xpos + 3 * b)) + offset;
      const Eigen::Vector3d moved = (skinning[static_cast<std::size_t>(v.joint)] * v.bind.homogeneous()).head<3>();
      worst_vertex = std::max(worst_vertex, (moved - expected).norm());
    }
  }
  EXPECT_LT(worst_bone, 1e-5) << "m";
  EXPECT_LT(worst_vertex, 1e-5) << "m";
}

// The planar human's joints carry the humanoid names of its own bodies (abdomen, chest,
// neck), and a robot gets none.
TEST(GltfSkin, HumanoidNamesOnlyOnHumans) {
  for (const char* name : {"human2d", "robot3d"}) {
    const auto model = SharedModel::from_file(std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/" + name + ".xml");
    const mjModel* m = model->get();
    const fs::path file = temp_dir() / (std::string(name) + "_names.glb");
    write_glb(file, {GltfMotion{m, {std::vector<double>(m->qpos0, m->qpos0 + m->nq)}, "M0", {0, 0, 0}}});
    const tinygltf::Model g = read_glb(file);
    std::map<std::string, std::string> humanoid;
    for (const auto& node : g.nodes)
      if (node.extras.Has("humanoid_bone")) humanoid[node.name] = node.extras.Get("humanoid_bone").Get<std::string>();
    if (std::string(name) == "human2d") {
      EXPECT_EQ(humanoid.size(), 17u);
      EXPECT_EQ(humanoid["chest"], "Chest");
      EXPECT_EQ(humanoid["neck"], "Neck");
      EXPECT_EQ(humanoid["shin_r"], "RightLowerLeg");
    } else {
      EXPECT_TRUE(humanoid.empty());
    }
    ASSERT_EQ(g.skins.size(), 1u);
    EXPECT_EQ(g.skins[0].joints.size(), static_cast<std::size_t>(m->nbody - 1));
  }
}

TEST(GltfExport, Human3dPushedSidewaysMatchesMujoco) {
  const auto motion = test_support::stance_motion("human3d", {0.2, 0.3, 0.0}, 1.5);
  const mjModel* m = motion.model->get();
  const auto frames = recorded_frames(motion.record, 17);
  const fs::path file = temp_dir() / "human3d.glb";
  write_glb(file, {GltfMotion{m, frames, "M0", {0, 0, 0}}}, rigid());
  const tinygltf::Model g = read_glb(file);
  ASSERT_EQ(g.nodes.size(), static_cast<std::size_t>(m->nbody));  // the motion's node + bodies
  EXPECT_EQ(g.nodes[0].name, "M0");
  EXPECT_EQ(g.nodes[1].name, "pelvis");
  ASSERT_EQ(g.animations.size(), 1u);
  // Every body has its mesh, one primitive per geom, in the geom's colour (linear sRGB).
  for (int b = 1; b < m->nbody; ++b) {
    const auto& node = g.nodes[static_cast<std::size_t>(b)];
    ASSERT_GE(node.mesh, 0) << node.name;
    int geoms = 0;
    for (int gi = 0; gi < m->ngeom; ++gi) geoms += m->geom_bodyid[gi] == b;
    EXPECT_EQ(g.meshes[static_cast<std::size_t>(node.mesh)].primitives.size(), static_cast<std::size_t>(geoms)) << node.name;
  }
  const auto& prim = g.meshes[static_cast<std::size_t>(g.nodes[1].mesh)].primitives[0];
  const auto& colour = g.materials[static_cast<std::size_t>(prim.material)].pbrMetallicRoughness.baseColorFactor;
  EXPECT_NEAR(colour[0], std::pow((0.8 + 0.055) / 1.055, 2.4), 1e-6);  // rgba 0.8 0.6 0.4
  // One keyframe per frame, 1/30 s apart.
  const auto& sampler = g.animations[0].samplers[0];
  const std::vector<float> times = floats(g, sampler.input);
  ASSERT_EQ(times.size(), frames.size());
  EXPECT_NEAR(times[1] - times[0], 1.0 / 30.0, 1e-6);
  // Only the root translates; every body turns.
  int translations = 0;
  for (const auto& c : g.animations[0].channels) translations += c.target_path == "translation";
  EXPECT_EQ(translations, 1);
  expect_matches_mujoco(m, frames, g, "");
}

TEST(GltfExport, SideBySideMotionsKeepTheirOwnBodies) {
  const auto human = test_support::stance_motion("human3d", {0.3, 0.0, 0.0}, 0.6);
  const auto bird = test_support::stance_motion("robot3d", {0.0, -0.3, 0.0}, 0.6);
  const auto hf = recorded_frames(human.record, 17), bf = recorded_frames(bird.record, 17);
  std::vector<GltfMotion> motions{{human.model->get(), hf, "M0", {0, 0, 0}},
                                  {bird.model->get(), bf, "M1", {0, -2.0, 0}}};
  EXPECT_GT(side_by_side_spacing(motions), 0.5);
  const fs::path file = temp_dir() / "both.glb";
  write_glb(file, motions, rigid());
  const tinygltf::Model g = read_glb(file);
  ASSERT_EQ(g.scenes.size(), 1u);
  ASSERT_EQ(g.scenes[0].nodes.size(), 2u);
  const auto& m1 = g.nodes[static_cast<std::size_t>(g.scenes[0].nodes[1])];
  EXPECT_EQ(m1.name, "M1");
  ASSERT_EQ(m1.translation.size(), 3u);
  EXPECT_NEAR(m1.translation[2], 2.0, 1e-12);  // MuJoCo -y is glTF +z
  EXPECT_GE(std::count_if(g.nodes.begin(), g.nodes.end(), [](const tinygltf::Node& n) { return n.name == "M1 tarsus_l"; }), 1);
  // Positions of the first motion's bodies are unaffected by the second's.
  expect_matches_mujoco(human.model->get(), hf, g, "M0 ");
}

TEST(GltfExport, PlanarHumanMatchesMujoco) {
  const auto model = SharedModel::from_file(std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.xml");
  const mjModel* m = model->get();
  std::vector<std::vector<double>> frames;
  for (int f = 0; f < 30; ++f) {
    std::vector<double> q(m->qpos0, m->qpos0 + m->nq);
    q[0] = 0.05 * f;
    q[1] = 0.3 * std::sin(0.2 * f);
    q[2] = 0.25 * f;  // a turn and a half of the root over the motion
    for (int j = 3; j < m->njnt; ++j) {
      const double lo = m->jnt_range[2 * j], hi = m->jnt_range[2 * j + 1];
      q[static_cast<std::size_t>(m->jnt_qposadr[j])] = lo + (hi - lo) * (0.5 + 0.4 * std::sin(0.3 * f + j));
    }
    frames.push_back(q);
  }
  const fs::path file = temp_dir() / "human2d.glb";
  write_glb(file, {GltfMotion{m, frames, "M0", {0, 0, 0}}});
  expect_matches_mujoco(m, frames, read_glb(file), "");
}

// A run whose bodies varied exports each body with its own proportions: the planar human
// with thighs 1.5 times as long has a thigh mesh longer by half a thigh, and its bodies are
// where MuJoCo puts them on the shaped model.
TEST(GltfExport, ShapedBodiesKeepTheirProportions) {
  const std::string root = DIVERSE_SOURCE_DIR;
  const auto spec = std::make_shared<CharacterSpec>(load_character_file(root + "/assets/characters/human2d.toml"));
  const auto base = SharedModel::from_file(spec->model);
  const ShapeSpace shapes(base->xml(), *spec);
  Eigen::VectorXd scales = shapes.identity();
  int thigh = -1;
  for (int p = 0; p < shapes.size(); ++p)
    if (shapes.specs()[static_cast<std::size_t>(p)].name == "shape.thigh") thigh = p;
  ASSERT_GE(thigh, 0);
  scales[thigh] = 1.5;
  const auto shaped = shapes.compile(scales);
  const mjModel* mb = base->get();
  const mjModel* ms = shaped->get();
  const std::vector<std::vector<double>> fb{std::vector<double>(mb->qpos0, mb->qpos0 + mb->nq)};
  const std::vector<std::vector<double>> fs{std::vector<double>(ms->qpos0, ms->qpos0 + ms->nq)};
  const fs::path file = temp_dir() / "shaped.glb";
  write_glb(file, {GltfMotion{mb, fb, "M0", {0, 0, 0}}, GltfMotion{ms, fs, "M1", {0, 0, 0}}}, rigid());
  const tinygltf::Model g = read_glb(file);
  auto thigh_extent = [&](const std::string& node_name) {
    for (const auto& node : g.nodes) {
      if (node.name != node_name) continue;
      const auto& prim = g.meshes[static_cast<std::size_t>(node.mesh)].primitives[0];
      const auto& a = g.accessors[static_cast<std::size_t>(prim.attributes.at("POSITION"))];
      return a.maxValues[1] - a.minValues[1];  // glTF y: along the hanging thigh
    }
    ADD_FAILURE() << node_name << " not found";
    return 0.0;
  };
  const int link = static_cast<int>(std::find(shapes.link_names().begin(), shapes.link_names().end(), "thigh_l") -
                                    shapes.link_names().begin());
  ASSERT_LT(link, static_cast<int>(shapes.link_names().size()));
  const double length = shapes.base_link_lengths()[link];
  EXPECT_NEAR(thigh_extent("M1 thigh_l") - thigh_extent("M0 thigh_l"), 0.5 * length, 1e-4);
  expect_matches_mujoco(ms, fs, g, "M1 ");
}

TEST(GltfExport, BadInput) {
  const auto model = SharedModel::from_file(std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.xml");
  EXPECT_THROW(write_glb(temp_dir() / "x.glb", {GltfMotion{model->get(), {}, "M0", {0, 0, 0}}}), std::invalid_argument);
  EXPECT_THROW(write_glb(temp_dir() / "x.glb", {GltfMotion{model->get(), {{1.0, 2.0}}, "M0", {0, 0, 0}}}),
               std::invalid_argument);
  try {
    write_glb("/proc/no/such/dir/x.glb", {GltfMotion{model->get(), {std::vector<double>(model->get()->qpos0, model->get()->qpos0 + model->get()->nq)}, "M0", {0, 0, 0}}});
    FAIL() << "expected a UserError";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/proc/no/such/dir/x.glb: cannot be written", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace diverse
