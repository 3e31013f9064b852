// Shape parameterization of the planar human: the identity shape is the base model, a
// scaled link moves exactly what hangs on it, masses never change, the character starts
// standing on its feet, and bad scales are one-line user errors.
#include "character/shape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "character/character.h"
#include "core/error.h"
#include "core/rng.h"
#include "physics/mujoco_guard.h"
#include "task/task.h"

namespace diverse {
namespace {

const std::string kModelPath = std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.xml";

// The planar human bound to a compiled model (its character file beside the MJCF).
Character human(const mjModel* m) {
  static const auto spec = std::make_shared<const CharacterSpec>(
      load_character_file(std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.toml"));
  return bind_character(spec, m, "model");
}
int body_id(const mjModel* m, const std::string& name) { return mj_name2id(m, mjOBJ_BODY, name.c_str()); }
// Distance (m) between two joints' anchors in the model's standing pose.
double anchor_distance(const Character& body, const std::string& a, const std::string& b) {
  const CharacterJoint *ja = nullptr, *jb = nullptr;
  for (const CharacterJoint& j : body.joints) {
    if (j.name == a) ja = &j;
    if (j.name == b) jb = &j;
  }
  double d2 = 0;
  for (int k = 0; k < 3; ++k) d2 += std::pow(ja->anchor0[k] - jb->anchor0[k], 2);
  return std::sqrt(d2);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

const ShapeSpace& space() {
  static const ShapeSpace s(read_text(kModelPath), kModelPath);
  return s;
}

// A random in-bounds shape.
Eigen::VectorXd random_shape(Rng& rng) {
  Eigen::VectorXd scales(ShapeSpace::size());
  for (int p = 0; p < ShapeSpace::size(); ++p) {
    const ParamSpec& s = space().specs()[p];
    scales[p] = s.lower + (s.upper - s.lower) * rng.uniform();
  }
  return scales;
}

Eigen::VectorXd with(int param, double scale) {
  Eigen::VectorXd scales = ShapeSpace::identity();
  scales[param] = scale;
  return scales;
}

template <typename T>
bool same(const T* a, const T* b, int n) {
  return std::memcmp(a, b, sizeof(T) * static_cast<size_t>(n)) == 0;
}

// Lowest and highest world z of a geom (capsule along its own z axis, or sphere) after
// mj_kinematics.
void geom_z_range(const mjModel* m, const mjData* d, int g, double* low, double* high) {
  const double z = d->geom_xpos[3 * g + 2];
  double reach = m->geom_size[3 * g];
  if (m->geom_type[g] == mjGEOM_CAPSULE)
    reach += std::fabs(d->geom_xmat[9 * g + 8]) * m->geom_size[3 * g + 1];
  *low = z - reach;
  *high = z + reach;
}

struct Standing {
  double feet_low, top, other_low;
};

// The standing pose (qpos0) of a compiled model, measured by MuJoCo's kinematics.
Standing measure(const mjModel* m) {
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
  const Character body = human(m);
  Standing s{1e9, -1e9, 1e9};
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->body_rootid[m->geom_bodyid[g]] != body.root_body) continue;
    double low = 0, high = 0;
    geom_z_range(m, d, g, &low, &high);
    const bool foot = body.is_foot_geom(m, g);
    (foot ? s.feet_low : s.other_low) = std::min(foot ? s.feet_low : s.other_low, low);
    s.top = std::max(s.top, high);
  }
  mj_deleteData(d);
  return s;
}

TEST(Shape, IdentityReproducesTheBaseModel) {
  const std::string base = read_text(kModelPath);
  EXPECT_EQ(space().xml(ShapeSpace::identity()), base);
  auto a = SharedModel::from_xml(base, "base");
  auto b = space().compile(ShapeSpace::identity());
  const mjModel* m = a->get();
  const mjModel* n = b->get();
  ASSERT_EQ(m->nbody, n->nbody);
  ASSERT_EQ(m->ngeom, n->ngeom);
  ASSERT_EQ(m->nq, n->nq);
  EXPECT_TRUE(same(m->body_pos, n->body_pos, 3 * m->nbody));
  EXPECT_TRUE(same(m->body_quat, n->body_quat, 4 * m->nbody));
  EXPECT_TRUE(same(m->body_ipos, n->body_ipos, 3 * m->nbody));
  EXPECT_TRUE(same(m->body_iquat, n->body_iquat, 4 * m->nbody));
  EXPECT_TRUE(same(m->body_mass, n->body_mass, m->nbody));
  EXPECT_TRUE(same(m->body_inertia, n->body_inertia, 3 * m->nbody));
  EXPECT_TRUE(same(m->geom_size, n->geom_size, 3 * m->ngeom));
  EXPECT_TRUE(same(m->geom_pos, n->geom_pos, 3 * m->ngeom));
  EXPECT_TRUE(same(m->geom_quat, n->geom_quat, 4 * m->ngeom));
  EXPECT_TRUE(same(m->qpos0, n->qpos0, m->nq));
  EXPECT_TRUE(same(m->dof_invweight0, n->dof_invweight0, m->nv));
}

TEST(Shape, ScaledNumbersReadBackExactly) {
  // A scale of 1.3 goes through text and MuJoCo's parser: the compiled offsets are the
  // products computed in double precision, bit for bit.
  const double r = 1.3;
  auto base = SharedModel::from_file(kModelPath);
  auto shaped = space().compile(with(kShapeUpperarm, r));
  const mjModel* m = base->get();
  const mjModel* n = shaped->get();
  for (const char* name : {"forearm_l", "forearm_r"}) {
    const int b = mj_name2id(m, mjOBJ_BODY, name);
    EXPECT_EQ(n->body_pos[3 * b + 0], m->body_pos[3 * b + 0] * r);
    EXPECT_EQ(n->body_pos[3 * b + 1], m->body_pos[3 * b + 1]);  // lateral offset stays
    EXPECT_EQ(n->body_pos[3 * b + 2], m->body_pos[3 * b + 2] * r);
  }
  const int g = mj_name2id(m, mjOBJ_GEOM, "upperarm_l");
  EXPECT_EQ(n->geom_size[3 * g], m->geom_size[3 * g]);                     // radius unchanged
  EXPECT_DOUBLE_EQ(n->geom_size[3 * g + 1], m->geom_size[3 * g + 1] * r);  // half length
}

TEST(Shape, LongerThighMovesKneeAndAnkleAndRaisesThePelvis) {
  const double r = 1.5;
  auto base = SharedModel::from_file(kModelPath);
  auto shaped = space().compile(with(kShapeThigh, r));
  const mjModel* m = base->get();
  const mjModel* n = shaped->get();
  const Character body = human(n);
  const int pelvis = body.root_body;
  const double added = 0.39 * (r - 1);
  EXPECT_NEAR(n->body_pos[3 * pelvis + 2], m->body_pos[3 * pelvis + 2] + added, 1e-12);
  EXPECT_NEAR(space().standing(with(kShapeThigh, r)).pelvis_z, 0.85 + added, 1e-12);
  mjData* d = mj_makeData(n);
  mj_forward(n, d);
  for (const char* side : {"_l", "_r"}) {
    const double hip = d->xpos[3 * body_id(n, std::string("thigh") + side) + 2];
    const double knee = d->xpos[3 * body_id(n, std::string("shin") + side) + 2];
    const double ankle = d->xpos[3 * body_id(n, std::string("foot") + side) + 2];
    EXPECT_NEAR(hip, 0.85 + added, 1e-12);
    EXPECT_NEAR(hip - knee, 0.39 * r, 1e-12);
    EXPECT_NEAR(knee - ankle, 0.39, 1e-12);
    EXPECT_NEAR(ankle, 0.07, 1e-12);  // the feet stay on the ground
  }
  // Shoulders and head ride up by the same amount; nothing else changes length.
  EXPECT_NEAR(d->xpos[3 * body_id(n, "chest") + 2], 1.10 + added, 1e-12);
  EXPECT_NEAR(anchor_distance(body, "hip_l", "knee_l"), 0.39 * r, 1e-12);
  EXPECT_NEAR(anchor_distance(body, "knee_l", "ankle_l"), 0.39, 1e-12);
  mj_deleteData(d);
}

TEST(Shape, MassesNeverChangeButInertiasFollowTheLengths) {
  auto base = SharedModel::from_file(kModelPath);
  const mjModel* m = base->get();
  Rng rng(7);
  for (int k = 0; k < 4; ++k) {
    const Eigen::VectorXd scales = random_shape(rng);
    auto shaped = space().compile(scales);
    const mjModel* n = shaped->get();
    EXPECT_TRUE(same(m->body_mass, n->body_mass, m->nbody));
    EXPECT_NEAR(human(n).total_mass, 80.0, 1e-9);
    // The thigh's inertia about its hinge axis grows with its length (capsule, fixed mass).
    const int thigh = mj_name2id(n, mjOBJ_BODY, "thigh_l");
    EXPECT_EQ(n->body_inertia[3 * thigh] > m->body_inertia[3 * thigh], scales[kShapeThigh] > 1.0);
  }
}

TEST(Shape, StandingHeightFollowsTheLengths) {
  const StandingShape s = space().standing(ShapeSpace::identity());
  EXPECT_NEAR(s.height, 1.60, 1e-12);
  EXPECT_EQ(s.pelvis_z, 0.85);
  EXPECT_NEAR(s.feet_z, 0.0, 1e-12);
  // A chest twice as long (0.23 m more) makes the character 0.23 m taller.
  EXPECT_NEAR(space().standing(with(kShapeChest, 2.0)).height, 1.83, 1e-12);
  // The head is a ball: the top of the head is 0.20 r above the head joint.
  EXPECT_NEAR(space().standing(with(kShapeHead, 0.5)).height, 1.60 - 0.5 * 0.27, 1e-12);
  // A short shin lowers everything above it; the feet stay at z = 0.
  const StandingShape low = space().standing(with(kShapeShin, 0.5));
  EXPECT_NEAR(low.pelvis_z, 0.85 - 0.195, 1e-12);
  EXPECT_NEAR(low.height, 1.60 - 0.195, 1e-12);
  // Lowest point above the feet: the shins' ends, 0.02 m up. The hands hang at 0.62 m;
  // upper arms and forearms 2.5 times as long reach through the floor.
  EXPECT_NEAR(s.lowest_other_z, 0.02, 1e-12);
  Eigen::VectorXd long_arms = with(kShapeUpperarm, 2.5);
  long_arms[kShapeForearm] = 2.5;
  EXPECT_NEAR(space().standing(long_arms).lowest_other_z, 0.62 - 1.5 * (0.29 + 0.24), 1e-12);
}

TEST(Shape, RandomShapesStartStandingOnTheirFeet) {
  install_mujoco_handlers();
  Rng rng(11);
  for (int k = 0; k < 5; ++k) {
    const Eigen::VectorXd scales = random_shape(rng);
    auto shaped = space().compile(scales);
    const Standing measured = measure(shaped->get());
    const StandingShape predicted = space().standing(scales);
    EXPECT_NEAR(measured.feet_low, 0.0, 1e-3);
    EXPECT_NEAR(measured.feet_low, predicted.feet_z, 1e-12);
    EXPECT_NEAR(measured.top - measured.feet_low, predicted.height, 1e-12);
    EXPECT_NEAR(measured.other_low, predicted.lowest_other_z, 1e-12);
    // Every shape is a valid model: 0.5 s with zero torque stays finite and warning-free.
    SimWorker worker(shaped);
    worker.reset();
    std::string error;
    for (int step = 0; step < 250; ++step) {
      ASSERT_TRUE(guarded_step(worker.model(), worker.data(), &error)) << error;
      ASSERT_FALSE(simulation_unstable(worker.model(), worker.data(), &error)) << error;
    }
  }
}

TEST(Shape, ParametersAreNamedAndRanged) {
  const auto& specs = space().specs();
  ASSERT_EQ(specs.size(), 10u);
  const char* names[] = {"shape.pelvis", "shape.abdomen", "shape.chest",    "shape.head",    "shape.thigh",
                         "shape.shin",   "shape.foot",    "shape.upperarm", "shape.forearm", "shape.hand"};
  for (int p = 0; p < 10; ++p) {
    EXPECT_EQ(specs[p].name, names[p]);
    EXPECT_EQ(specs[p].unit, "scale");
    EXPECT_EQ(specs[p].upper, 2.5);
    // 0.4 everywhere but the head group, whose 0.07 m neck needs r >= 0.03 / 0.07.
    EXPECT_EQ(specs[p].lower, p == kShapeHead ? 0.429 : 0.4) << names[p];
  }
  // Beside the controller's parameters in one set.
  std::vector<ParamSpec> all = {ParamSpec{"crouch.knee", -2.6, 0, "rad"}};
  std::vector<double> values = {-1.0};
  for (int p = 0; p < 10; ++p) {
    all.push_back(specs[p]);
    values.push_back(1.0 + 0.1 * p);
  }
  const ParameterSet set(all, values);
  const Eigen::VectorXd scales = space().scales_from(set);
  for (int p = 0; p < 10; ++p) EXPECT_DOUBLE_EQ(scales[p], 1.0 + 0.1 * p);
  EXPECT_THROW(space().scales_from(ParameterSet({all[0]}, {-1.0})), std::out_of_range);
}

TEST(Shape, LinkLengthsAreTheScaledLinks) {
  auto base = SharedModel::from_file(kModelPath);
  const mjModel* m = base->get();
  const Character body = human(m);
  // One length per link, in Character::links (model) order.
  ASSERT_EQ(space().link_names().size(), body.links.size());
  for (size_t i = 0; i < body.links.size(); ++i) {
    EXPECT_EQ(space().link_names()[i], mj_id2name(m, mjOBJ_BODY, body.links[i]));
  }
  const std::vector<std::pair<std::string, double>> expected = {
      {"pelvis", 0.10},    {"thigh_l", 0.39},    {"shin_l", 0.39},    {"foot_l", 0.21}, {"thigh_r", 0.39},
      {"shin_r", 0.39},    {"foot_r", 0.21},     {"abdomen", 0.15},   {"chest", 0.23},  {"neck", 0.07},
      {"head", 0.20},      {"upperarm_l", 0.29}, {"forearm_l", 0.24}, {"hand_l", 0.12}, {"upperarm_r", 0.29},
      {"forearm_r", 0.24}, {"hand_r", 0.12}};
  ASSERT_EQ(expected.size(), 17u);
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(space().link_names()[i], expected[i].first);
    EXPECT_NEAR(space().base_link_lengths()[i], expected[i].second, 1e-12) << expected[i].first;
  }
  Rng rng(3);
  const Eigen::VectorXd scales = random_shape(rng);
  const Eigen::VectorXd lengths = space().link_lengths(scales);
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(lengths[i], scales[space().link_params()[i]] * space().base_link_lengths()[i]);
  }
  // The compiled model agrees: hip to knee, and elbow to wrist, are the scaled lengths.
  auto shaped = space().compile(scales);
  const mjModel* n = shaped->get();
  EXPECT_NEAR(std::fabs(n->body_pos[3 * mj_name2id(n, mjOBJ_BODY, "shin_r") + 2]), lengths[4], 1e-15);
  EXPECT_NEAR(std::fabs(n->body_pos[3 * mj_name2id(n, mjOBJ_BODY, "hand_l") + 2]), lengths[12], 1e-15);
  // At the lower bounds no link is shorter than 0.03 m.
  Eigen::VectorXd lowest(ShapeSpace::size());
  for (int p = 0; p < ShapeSpace::size(); ++p) lowest[p] = space().specs()[p].lower;
  EXPECT_GE(space().link_lengths(lowest).minCoeff(), kShapeMinLinkLength);
  EXPECT_NO_THROW(space().compile(lowest));
}

TEST(Shape, OutOfRangeScalesAreOneLineErrors) {
  auto message = [](const Eigen::VectorXd& scales) {
    try {
      space().xml(scales, "params.json");
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(with(kShapeThigh, 2.7)),
            "params.json: shape.thigh: expected a scale in [0.4, 2.5], got 2.7");
  EXPECT_EQ(message(with(kShapePelvis, 0.39)),
            "params.json: shape.pelvis: expected a scale in [0.4, 2.5], got 0.39");
  // 0.41 would make the neck 0.0287 m long.
  EXPECT_EQ(message(with(kShapeHead, 0.41)),
            "params.json: shape.head: expected a scale in [0.429, 2.5], got 0.41");
  EXPECT_EQ(message(with(kShapeHand, std::nan(""))),
            "params.json: shape.hand: expected a scale in [0.4, 2.5], got nan");
  EXPECT_EQ(message(with(kShapeHand, 2.5)), "no error");
  EXPECT_THROW(space().compile(with(kShapeFoot, 0.1), "params.json"), UserError);
  EXPECT_THROW(space().validate(Eigen::VectorXd::Ones(9), "params.json"), std::invalid_argument);
}

TEST(Shape, ModelsOutsideTheShapeRulesAreRejected) {
  const std::string base = read_text(kModelPath);
  auto message = [](const std::string& xml) {
    try {
      ShapeSpace s(xml, "human.xml");
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string xml = base;
    const size_t at = xml.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return xml.replace(at, from.size(), to);
  };
  EXPECT_EQ(message(replace("<body name=\"hand_r\"", "<body name=\"paw_r\"")),
            "human.xml: body 'paw_r': expected one of the planar human's 17 links");
  EXPECT_EQ(
      message(replace("size=\"0.03\" mass=\"0.48\"/>", "size=\"0.03\" density=\"900\"/>")),
      "human.xml: geom 'hand_l': expected a mass attribute (link masses stay fixed when shapes change)");
  EXPECT_EQ(
      message(replace("<body name=\"neck\" pos=\"0 0 0.23\">",
                      "<body name=\"neck\" pos=\"0 0 0.23\" euler=\"0 1 0\">")),
      "human.xml: body 'neck': euler: expected no rotation (the shape rules scale axis-aligned frames)");
  EXPECT_EQ(
      message(replace("<body name=\"chest\" pos=\"0 0 0.15\">", "<body name=\"chest\" pos=\"0 0 zero\">")),
      "human.xml: body 'chest': pos: expected numbers, got \"0 0 zero\"");
  EXPECT_EQ(message(replace("</worldbody>", "</world>")),
            "human.xml: line 135: malformed XML: </world> does not close the open element");
}

TEST(Shape, SceneObjectsAreCopiedThrough) {
  // A task scene is the character plus boxes: only the character changes.
  const Task task = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_onto.toml");
  const ShapeSpace scene(scene_xml(task), task.model);
  auto base = SharedModel::from_xml(scene_xml(task), "scene");
  auto shaped = scene.compile(with(kShapeShin, 0.8));
  const mjModel* m = base->get();
  const mjModel* n = shaped->get();
  ASSERT_EQ(m->ngeom, n->ngeom);
  const Character body = human(m);
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->body_rootid[m->geom_bodyid[g]] == body.root_body) continue;
    EXPECT_TRUE(same(m->geom_pos + 3 * g, n->geom_pos + 3 * g, 3)) << g;
    EXPECT_TRUE(same(m->geom_size + 3 * g, n->geom_size + 3 * g, 3)) << g;
  }
}

TEST(Shape, CompilesFromSeveralThreadsAlike) {
  Rng rng(5);
  std::vector<Eigen::VectorXd> shapes;
  for (int k = 0; k < 4; ++k) shapes.push_back(random_shape(rng));
  std::vector<std::vector<double>> serial, parallel(shapes.size());
  for (const auto& s : shapes) {
    auto model = space().compile(s);
    const mjModel* m = model->get();
    serial.emplace_back(m->body_inertia, m->body_inertia + 3 * m->nbody);
  }
  std::vector<std::thread> threads;
  for (size_t t = 0; t < 2; ++t) {
    threads.emplace_back([&, t] {
      for (size_t k = t; k < shapes.size(); k += 2) {
        auto model = space().compile(shapes[k]);
        const mjModel* m = model->get();
        parallel[k].assign(m->body_inertia, m->body_inertia + 3 * m->nbody);
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(serial, parallel);
}

TEST(Shape, ExportedShapedModelsReplayIdentically) {
  // The shaped text is the model's export: written to a file and loaded back, it
  // simulates bit for bit like the model compiled in memory. (MuJoCo's own writer,
  // mj_saveLastXML, keeps 6 significant digits, which a shaped model does not survive.)
  Rng rng(13);
  const Eigen::VectorXd scales = random_shape(rng);
  auto shaped = space().compile(scales);
  const std::string path = testing::TempDir() + "shape_exported_model.xml";
  {
    std::ofstream out(path, std::ios::binary);
    out << shaped->xml();
  }
  auto reloaded = SharedModel::from_file(path);
  std::remove(path.c_str());
  const mjModel* m = shaped->get();
  const mjModel* n = reloaded->get();
  ASSERT_EQ(m->nbody, n->nbody);
  EXPECT_TRUE(same(m->body_pos, n->body_pos, 3 * m->nbody));
  EXPECT_TRUE(same(m->body_inertia, n->body_inertia, 3 * m->nbody));
  EXPECT_TRUE(same(m->geom_size, n->geom_size, 3 * m->ngeom));
  SimWorker a(shaped), b(reloaded);
  a.reset();
  b.reset();
  for (int step = 0; step < 200; ++step) {
    for (int i = 0; i < m->nu; ++i) a.data()->ctrl[i] = b.data()->ctrl[i] = 20.0 * std::sin(0.05 * step + i);
    mj_step(a.model(), a.data());
    mj_step(b.model(), b.data());
  }
  EXPECT_FALSE(same(a.data()->qpos, m->qpos0, m->nq));  // it did move
  EXPECT_TRUE(same(a.data()->qpos, b.data()->qpos, m->nq));
  EXPECT_TRUE(same(a.data()->qvel, b.data()->qvel, m->nv));
}

TEST(Shape, OneCallFormMatchesTheSpace) {
  const std::string base = read_text(kModelPath);
  EXPECT_EQ(shaped_model_xml(base, with(kShapeForearm, 1.7)), space().xml(with(kShapeForearm, 1.7)));
}

}  // namespace
}  // namespace diverse
