// Shape parameterization from the character file: for the planar human, the identity
// shape is the base model, a scaled link moves exactly what hangs on it, masses never
// change, the character starts standing on its feet, and bad scales are one-line user
// errors; a smaller planar biped gets its own parameters from its own [shape] section; and
// a character that cannot vary its shape says so in one line.
#include "character/shape.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "character/character.h"
#include "core/error.h"
#include "support/text_files.h"
#include "core/rng.h"
#include "physics/mujoco_guard.h"
#include "support/cli.h"
#include "task/task.h"

namespace diverse {
namespace {

namespace fs = std::filesystem;

const std::string kModelPath = std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.xml";

// The planar human's character file, parsed.
const std::shared_ptr<const CharacterSpec>& human_spec() {
  static const auto spec = std::make_shared<const CharacterSpec>(
      load_character_file(std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/human2d.toml"));
  return spec;
}

// The planar human bound to a compiled model (its character file beside the MJCF).
Character human(const mjModel* m) { return bind_character(human_spec(), m, "model"); }
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

using test_files::read_text;
using test_files::write_text;

const ShapeSpace& space() {
  static const ShapeSpace s(read_text(kModelPath), *human_spec(), kModelPath);
  return s;
}

// The index of parameter "shape.NAME" in a shape space.
int param(const ShapeSpace& shapes, const std::string& name) {
  for (size_t p = 0; p < shapes.specs().size(); ++p)
    if (shapes.specs()[p].name == "shape." + name) return static_cast<int>(p);
  ADD_FAILURE() << "no shape parameter " << name;
  return 0;
}
int param(const std::string& name) { return param(space(), name); }

// A random in-bounds shape.
Eigen::VectorXd random_shape(Rng& rng, const ShapeSpace& shapes = space()) {
  Eigen::VectorXd scales(shapes.size());
  for (int p = 0; p < shapes.size(); ++p) {
    const ParamSpec& s = shapes.specs()[static_cast<size_t>(p)];
    scales[p] = s.lower + (s.upper - s.lower) * rng.uniform();
  }
  return scales;
}

// The planar human's identity shape with one parameter, "shape.NAME", set.
Eigen::VectorXd with(const std::string& name, double scale) {
  Eigen::VectorXd scales = space().identity();
  scales[param(name)] = scale;
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
Standing measure(const mjModel* m, const Character& body) {
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
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
  EXPECT_EQ(space().xml(space().identity()), base);
  auto a = SharedModel::from_xml(base, "base");
  auto b = space().compile(space().identity());
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
  auto shaped = space().compile(with("upperarm", r));
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
  auto shaped = space().compile(with("thigh", r));
  const mjModel* m = base->get();
  const mjModel* n = shaped->get();
  const Character body = human(n);
  const int pelvis = body.root_body;
  const double added = 0.39 * (r - 1);
  EXPECT_NEAR(n->body_pos[3 * pelvis + 2], m->body_pos[3 * pelvis + 2] + added, 1e-12);
  EXPECT_NEAR(space().standing(with("thigh", r)).pelvis_z, 0.85 + added, 1e-12);
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
    EXPECT_EQ(n->body_inertia[3 * thigh] > m->body_inertia[3 * thigh], scales[param("thigh")] > 1.0);
  }
}

TEST(Shape, StandingHeightFollowsTheLengths) {
  const StandingShape s = space().standing(space().identity());
  EXPECT_NEAR(s.height, 1.60, 1e-12);
  EXPECT_EQ(s.pelvis_z, 0.85);
  EXPECT_NEAR(s.feet_z, 0.0, 1e-12);
  // A chest twice as long (0.23 m more) makes the character 0.23 m taller.
  EXPECT_NEAR(space().standing(with("chest", 2.0)).height, 1.83, 1e-12);
  // The head is a ball: the top of the head is 0.20 r above the head joint.
  EXPECT_NEAR(space().standing(with("head", 0.5)).height, 1.60 - 0.5 * 0.27, 1e-12);
  // A short shin lowers everything above it; the feet stay at z = 0.
  const StandingShape low = space().standing(with("shin", 0.5));
  EXPECT_NEAR(low.pelvis_z, 0.85 - 0.195, 1e-12);
  EXPECT_NEAR(low.height, 1.60 - 0.195, 1e-12);
  // Lowest point above the feet: the shins' ends, 0.02 m up. The hands hang at 0.62 m;
  // upper arms and forearms 2.5 times as long reach through the floor.
  EXPECT_NEAR(s.lowest_other_z, 0.02, 1e-12);
  Eigen::VectorXd long_arms = with("upperarm", 2.5);
  long_arms[param("forearm")] = 2.5;
  EXPECT_NEAR(space().standing(long_arms).lowest_other_z, 0.62 - 1.5 * (0.29 + 0.24), 1e-12);
}

TEST(Shape, RandomShapesStartStandingOnTheirFeet) {
  install_mujoco_handlers();
  Rng rng(11);
  for (int k = 0; k < 5; ++k) {
    const Eigen::VectorXd scales = random_shape(rng);
    auto shaped = space().compile(scales);
    const Standing measured = measure(shaped->get(), human(shaped->get()));
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
    EXPECT_EQ(specs[p].lower, specs[p].name == "shape.head" ? 0.429 : 0.4) << names[p];
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
  Eigen::VectorXd lowest(space().size());
  for (int p = 0; p < space().size(); ++p) lowest[p] = space().specs()[p].lower;
  EXPECT_GE(space().link_lengths(lowest).minCoeff(), human_spec()->shape_min_link_length);
  EXPECT_EQ(human_spec()->shape_min_link_length, 0.03);
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
  EXPECT_EQ(message(with("thigh", 2.7)),
            "params.json: shape.thigh: expected a scale in [0.4, 2.5], got 2.7");
  EXPECT_EQ(message(with("pelvis", 0.39)),
            "params.json: shape.pelvis: expected a scale in [0.4, 2.5], got 0.39");
  // 0.41 would make the neck 0.0287 m long.
  EXPECT_EQ(message(with("head", 0.41)),
            "params.json: shape.head: expected a scale in [0.429, 2.5], got 0.41");
  EXPECT_EQ(message(with("hand", std::nan(""))),
            "params.json: shape.hand: expected a scale in [0.4, 2.5], got nan");
  EXPECT_EQ(message(with("hand", 2.5)), "no error");
  EXPECT_THROW(space().compile(with("foot", 0.1), "params.json"), UserError);
  EXPECT_THROW(space().validate(Eigen::VectorXd::Ones(9), "params.json"), std::invalid_argument);
}

TEST(Shape, ModelsOutsideTheShapeRulesAreRejected) {
  const std::string base = read_text(kModelPath);
  auto message = [](const std::string& xml) {
    try {
      ShapeSpace s(xml, *human_spec(), "human.xml");
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
  // A link the character file's [shape] section names must be in the model.
  EXPECT_EQ(message(replace("<body name=\"hand_r\"", "<body name=\"paw_r\"")),
            human_spec()->file +
                ": shape.parameters[9].links: expected a body of the model human.xml, but it has no body 'hand_r'");
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
  const long worldbody_line = 1 + std::count(base.begin(), base.begin() + static_cast<long>(base.find("</worldbody>")), '\n');
  EXPECT_EQ(message(replace("</worldbody>", "</world>")),
            "human.xml: line " + std::to_string(worldbody_line) +
                ": malformed XML: </world> does not close the open element");
}

TEST(Shape, SceneObjectsAreCopiedThrough) {
  // A task scene is the character plus boxes: only the character changes.
  const Task task = load_task(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_onto.toml");
  const ShapeSpace scene(scene_xml(task), *task.character_spec, task.model);
  auto base = SharedModel::from_xml(scene_xml(task), "scene");
  auto shaped = scene.compile(with("shin", 0.8));
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
  EXPECT_EQ(shaped_model_xml(base, *human_spec(), with("forearm", 1.7)), space().xml(with("forearm", 1.7)));
}

// ---------------------------------------------------------------------------------------
// A second planar character: a 5-link biped (torso, two legs, two feet) with 2 shape
// parameters; its torso is in none and keeps its length.

const char* kBipedXml = R"(<mujoco model="biped5">
  <compiler angle="radian" inertiafromgeom="true" autolimits="true"/>
  <option timestep="0.002" integrator="Euler" gravity="0 0 -9.81"/>
  <default>
    <joint type="hinge" axis="0 -1 0" armature="0.01" limited="true" damping="5"/>
    <geom type="capsule" contype="1" conaffinity="0" condim="3" friction="1 0.005 0.0001"/>
    <motor ctrllimited="false"/>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="20 2 0.1" contype="0" conaffinity="1"/>
    <body name="torso" pos="0 0 0.65">
      <joint name="rootx" type="slide" axis="1 0 0" limited="false" armature="0" damping="0"/>
      <joint name="rootz" type="slide" axis="0 0 1" limited="false" armature="0" damping="0"/>
      <joint name="rooty" type="hinge" axis="0 -1 0" limited="false" armature="0" damping="0"/>
      <geom name="torso" fromto="0 0 -0.05 0 0 0.4" size="0.08" mass="20"/>
      <body name="leg_l" pos="0 0.08 -0.05">
        <joint name="hip_l" range="-1 1"/>
        <geom name="leg_l" fromto="0 0 0 0 0 -0.5" size="0.04" mass="4"/>
        <body name="foot_l" pos="0 0 -0.5">
          <joint name="ankle_l" range="-0.8 0.8"/>
          <geom name="foot_l" fromto="-0.04 0 -0.06 0.12 0 -0.06" size="0.04" mass="1"/>
        </body>
      </body>
      <body name="leg_r" pos="0 -0.08 -0.05">
        <joint name="hip_r" range="-1 1"/>
        <geom name="leg_r" fromto="0 0 0 0 0 -0.5" size="0.04" mass="4"/>
        <body name="foot_r" pos="0 0 -0.5">
          <joint name="ankle_r" range="-0.8 0.8"/>
          <geom name="foot_r" fromto="-0.04 0 -0.06 0.12 0 -0.06" size="0.04" mass="1"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="tau_hip_l" joint="hip_l" forcelimited="true" forcerange="-100 100"/>
    <motor name="tau_ankle_l" joint="ankle_l" forcelimited="true" forcerange="-50 50"/>
    <motor name="tau_hip_r" joint="hip_r" forcelimited="true" forcerange="-100 100"/>
    <motor name="tau_ankle_r" joint="ankle_r" forcelimited="true" forcerange="-50 50"/>
  </actuator>
</mujoco>
)";

const char* kBipedRoot = R"([root]
kind = "planar"
body = "torso"
x = "rootx"
z = "rootz"
pitch = "rooty"
)";

const char* kBipedBody = R"(
[[groups]]
name = "hip"
role = "hip"
plane = "sagittal"
joints = ["hip_l", "hip_r"]
wja = 1.0
kp = 0.0
kd = 0.0

[[groups]]
name = "ankle"
role = "ankle"
plane = "sagittal"
joints = ["ankle_l", "ankle_r"]
wja = 0.0
kp = 0.0
kd = 0.0

[feet]
bodies = ["foot_l", "foot_r"]
)";

const char* kBipedShape = R"(
[shape]
min_link_length = 0.1

[[shape.parameters]]
name = "leg"
links = ["leg_l", "leg_r"]
min = 0.5
max = 1.5

[[shape.parameters]]
name = "foot"
links = ["foot_l", "foot_r"]
min = 0.4
max = 2.0
)";

// Writes the biped's model and a character file (header, root, body, shape sections as
// given) into a fresh directory; returns the character file's path.
std::string write_biped(const std::string& name, const std::string& root = kBipedRoot,
                        const std::string& shape = kBipedShape, const std::string& xml = kBipedXml) {
  const fs::path dir = fs::path(testing::TempDir()) / ("shape_biped_" + name);
  fs::create_directories(dir);
  write_text((dir / "biped5.xml").string(), xml);
  const std::string toml = "name = \"biped5\"\nmodel = \"biped5.xml\"\n\n" + root + kBipedBody + shape;
  write_text((dir / "biped5.toml").string(), toml);
  return (dir / "biped5.toml").string();
}

// The error message of building a shape space ("no error" if none).
std::string shape_error(const std::string& character_file) {
  try {
    const CharacterSpec spec = load_character_file(character_file);
    ShapeSpace s(read_text(spec.model), spec, spec.model);
  } catch (const UserError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ShapeBiped, ItsOwnParametersRangesAndLengths) {
  const auto spec = std::make_shared<const CharacterSpec>(load_character_file(write_biped("ranges")));
  const ShapeSpace biped(read_text(spec->model), *spec, spec->model);
  ASSERT_EQ(biped.size(), 2);
  EXPECT_EQ(biped.identity(), Eigen::VectorXd::Ones(2));
  // File order; the foot's range starts where its 0.16 m capsule would be 0.1 m long.
  EXPECT_EQ(biped.specs()[0].name, "shape.leg");
  EXPECT_EQ(biped.specs()[0].unit, "scale");
  EXPECT_EQ(biped.specs()[0].lower, 0.5);
  EXPECT_EQ(biped.specs()[0].upper, 1.5);
  EXPECT_EQ(biped.specs()[1].name, "shape.foot");
  EXPECT_EQ(biped.specs()[1].lower, 0.625);
  EXPECT_EQ(biped.specs()[1].upper, 2.0);
  // Every body of the character is a link, in model order; the torso is in no parameter.
  const std::vector<std::string> names = {"torso", "leg_l", "foot_l", "leg_r", "foot_r"};
  EXPECT_EQ(biped.link_names(), names);
  EXPECT_EQ(biped.link_params(), (std::vector<int>{-1, 0, 1, 0, 1}));
  const Eigen::VectorXd base = biped.base_link_lengths();
  ASSERT_EQ(base.size(), 5);
  EXPECT_NEAR(base[0], 0.05, 1e-15);  // torso origin to the hips
  EXPECT_NEAR(base[1], 0.5, 1e-15);   // hip to ankle
  EXPECT_NEAR(base[2], 0.16, 1e-15);  // the foot capsule's axis
  Eigen::VectorXd scales(2);
  scales << 1.4, 0.7;
  const Eigen::VectorXd lengths = biped.link_lengths(scales);
  EXPECT_EQ(lengths[0], base[0]);
  EXPECT_EQ(lengths[1], 1.4 * base[1]);
  EXPECT_EQ(lengths[2], 0.7 * base[2]);
  EXPECT_EQ(lengths[4], 0.7 * base[4]);
  // Its bind agrees on the links; the identity shape is its model byte for byte.
  auto model = SharedModel::from_file(spec->model);
  const Character body = bind_character(spec, model->get(), spec->model);
  ASSERT_EQ(body.links.size(), names.size());
  for (size_t i = 0; i < names.size(); ++i) EXPECT_EQ(mj_id2name(model->get(), mjOBJ_BODY, body.links[i]), names[i]);
  EXPECT_EQ(biped.xml(biped.identity()), std::string(kBipedXml));
  Eigen::VectorXd too_long(2);
  too_long << 1.6, 1.0;
  try {
    biped.validate(too_long, "params.json");
    ADD_FAILURE() << "no error";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), "params.json: shape.leg: expected a scale in [0.5, 1.5], got 1.6");
  }
}

TEST(ShapeBiped, TheUnlistedTorsoKeepsItsLengthAndScaledBodiesStandOnTheirFeet) {
  install_mujoco_handlers();
  const auto spec = std::make_shared<const CharacterSpec>(load_character_file(write_biped("stands")));
  const ShapeSpace biped(read_text(spec->model), *spec, spec->model);
  auto base = SharedModel::from_file(spec->model);
  const mjModel* m = base->get();
  const StandingShape s0 = biped.standing(biped.identity());
  EXPECT_EQ(s0.pelvis_z, 0.65);
  EXPECT_NEAR(s0.feet_z, 0.0, 1e-15);
  EXPECT_NEAR(s0.height, 0.65 + 0.4 + 0.08, 1e-12);
  Rng rng(17);
  for (int k = 0; k < 4; ++k) {
    const Eigen::VectorXd scales = random_shape(rng, biped);
    auto shaped = biped.compile(scales);
    const mjModel* n = shaped->get();
    const Character body = bind_character(spec, n, "shaped");
    // The torso is not rescaled: its capsule and the hips' offsets stay as written.
    const int torso = body_id(n, "torso");
    const int torso_geom = mj_name2id(n, mjOBJ_GEOM, "torso");
    EXPECT_TRUE(same(m->geom_size + 3 * torso_geom, n->geom_size + 3 * torso_geom, 3));
    EXPECT_TRUE(same(m->geom_pos + 3 * torso_geom, n->geom_pos + 3 * torso_geom, 3));
    for (const char* leg : {"leg_l", "leg_r"}) {
      const int b = body_id(n, leg);
      EXPECT_TRUE(same(m->body_pos + 3 * b, n->body_pos + 3 * b, 3)) << leg;
      EXPECT_EQ(n->body_pos[3 * body_id(n, leg == std::string("leg_l") ? "foot_l" : "foot_r") + 2], -0.5 * scales[0]);
    }
    EXPECT_EQ(biped.link_lengths(scales)[0], biped.base_link_lengths()[0]);
    EXPECT_TRUE(same(m->body_mass, n->body_mass, m->nbody));
    // Standing: the feet's lowest point stays at z = 0, as predicted.
    const StandingShape predicted = biped.standing(scales);
    EXPECT_NEAR(predicted.pelvis_z, 0.65 + 0.5 * (scales[0] - 1) + 0.06 * (scales[1] - 1), 1e-12);
    EXPECT_NEAR(n->body_pos[3 * torso + 2], predicted.pelvis_z, 1e-15);
    const Standing measured = measure(n, body);
    EXPECT_NEAR(measured.feet_low, 0.0, 1e-12);
    EXPECT_NEAR(measured.top - measured.feet_low, predicted.height, 1e-12);
    EXPECT_NEAR(measured.other_low, predicted.lowest_other_z, 1e-12);
    // It simulates: 0.2 s with zero torque stays finite and warning-free.
    SimWorker worker(shaped);
    worker.reset();
    std::string error;
    for (int step = 0; step < 100; ++step) {
      ASSERT_TRUE(guarded_step(worker.model(), worker.data(), &error)) << error;
      ASSERT_FALSE(simulation_unstable(worker.model(), worker.data(), &error)) << error;
    }
  }
}

TEST(ShapeBiped, OnlyAPlanarCharacterWithShapeParametersAndKnownLinksCanVaryItsShape) {
  // A free root: the shape rules scale the sagittal plane of a planar character.
  const std::string free_root = write_biped("free", "[root]\nkind = \"free\"\nbody = \"torso\"\njoint = \"root\"\n");
  EXPECT_EQ(shape_error(free_root),
            free_root + ": shape: expected a planar character (the shape rules scale the sagittal plane)");
  // No [shape] section.
  const std::string none = write_biped("none", kBipedRoot, "");
  EXPECT_EQ(shape_error(none), none + ": shape: expected [shape] parameters in the character file for --vary "
                                      "shape (this character has none)");
  // A link the model lacks, and a body that is not part of the character.
  std::string shape = kBipedShape;
  shape.replace(shape.find("\"foot_l\", \"foot_r\""), 18, "\"foot_l\", \"foot_r\", \"toe_l\"");
  const std::string unknown = write_biped("unknown", kBipedRoot, shape);
  const std::string model = (fs::path(unknown).parent_path() / "biped5.xml").string();
  EXPECT_EQ(shape_error(unknown), unknown + ": shape.parameters[1].links: expected a body of the model " + model +
                                      ", but it has no body 'toe_l'");
  std::string with_crate = kBipedXml;
  with_crate.replace(with_crate.find("  </worldbody>"), 0,
                     "    <body name=\"crate\" pos=\"1 0 0.1\"><geom type=\"box\" size=\"0.1 0.1 0.1\"/></body>\n");
  shape = kBipedShape;
  shape.replace(shape.find("\"leg_l\", \"leg_r\""), 16, "\"leg_l\", \"leg_r\", \"crate\"");
  const std::string crate = write_biped("crate", kBipedRoot, shape, with_crate);
  EXPECT_EQ(shape_error(crate), crate + ": shape.parameters[0].links: expected a link of the character (a body "
                                        "inside 'torso'), got 'crate'");
  // The well-formed biped has no error.
  EXPECT_EQ(shape_error(write_biped("fine")), "no error");
}

TEST(ShapeBiped, VaryShapeOnACharacterWithoutShapeParametersIsOneLineWithExitCodeTwo) {
  // The planar human without its [shape] section, and jump_high on it.
  const fs::path dir = fs::path(testing::TempDir()) / "shape_no_shape_cli";
  fs::create_directories(dir);
  const std::string characters = std::string(DIVERSE_SOURCE_DIR) + "/assets/characters/";
  std::string toml = read_text(characters + "human2d.toml");
  const size_t at = toml.find("# Shape parameters");
  ASSERT_NE(at, std::string::npos);
  toml.erase(at);
  ASSERT_EQ(toml.find("[shape]"), std::string::npos);
  const std::string character = (dir / "human2d.toml").string();
  write_text(character, toml);
  write_text((dir / "human2d.xml").string(), read_text(characters + "human2d.xml"));
  std::string task = read_text(std::string(DIVERSE_SOURCE_DIR) + "/tasks/jump_high.toml");
  auto edit = [&](const std::string& from, const std::string& to) {
    const size_t pos = task.find(from);
    ASSERT_NE(pos, std::string::npos) << from;
    task.replace(pos, from.size(), to);
  };
  const std::string tasks = std::string(DIVERSE_SOURCE_DIR) + "/tasks/";
  edit("character = \"../assets/characters/human2d.toml\"", "character = \"human2d.toml\"");
  edit("skill = \"../skills/", "skill = \"" + std::string(DIVERSE_SOURCE_DIR) + "/skills/");
  edit("m0 = \"jump_high.m0.json\"", "m0 = \"" + tasks + "jump_high.m0.json\"");
  edit("base = \"jump_high_start.json\"", "base = \"" + tasks + "jump_high_start.json\"");
  write_text((dir / "task.toml").string(), task);
  const fs::path out = dir / "out";
  const cli_test::CliResult r = cli_test::run_cli("run " + (dir / "task.toml").string() +
                                                  " --vary shape --generations 1 --threads 1 --out " +
                                                  out.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(r.output, "diverse: error: " + character +
                          ": shape: expected [shape] parameters in the character file for --vary shape "
                          "(this character has none)\n");
  EXPECT_FALSE(fs::exists(out / "run.json"));  // refused before any work
}

}  // namespace
}  // namespace diverse
