#include "io/gltf.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <numbers>
#include <stdexcept>

#include "core/error.h"
#include "io/files.h"

namespace diverse {
namespace {

constexpr double kPi = std::numbers::pi;

using Vec3 = std::array<double, 3>;

struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

// MuJoCo axes to glTF axes: (x, y, z) -> (x, z, -y); quaternions (w, x, y, z) likewise on
// their vector part, since the map is a proper rotation.
Vec3 to_gltf(const double* v) { return {v[0], v[2], -v[1]}; }
std::array<double, 4> quat_to_gltf_xyzw(const double* q) {
  double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(n > 0)) n = 1;
  return {q[1] / n, q[3] / n, -q[2] / n, q[0] / n};
}

// sRGB colour component to linear (glTF's baseColorFactor is linear).
double linear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// A triangle mesh in one geom's frame.
struct TriMesh {
  std::vector<Vec3> position, normal;
  std::vector<std::uint32_t> index;
};

// A surface of revolution about z from a profile of (r, z, normal r, normal z) points,
// bottom to top; each profile point is a ring of `slices` vertices (plus a seam copy).
void lathe(TriMesh& mesh, const std::vector<std::array<double, 4>>& profile, int slices) {
  const auto base = static_cast<std::uint32_t>(mesh.position.size());
  for (const auto& p : profile) {
    for (int s = 0; s <= slices; ++s) {
      const double a = 2 * kPi * s / slices;
      const double c = std::cos(a), sn = std::sin(a);
      mesh.position.push_back({p[0] * c, p[0] * sn, p[1]});
      const double nx = p[2] * c, ny = p[2] * sn, nz = p[3];
      const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
      mesh.normal.push_back(len > 0 ? Vec3{nx / len, ny / len, nz / len} : Vec3{0, 0, p[3] >= 0 ? 1.0 : -1.0});
    }
  }
  const auto ring = static_cast<std::uint32_t>(slices + 1);
  for (std::uint32_t r = 0; r + 1 < profile.size(); ++r) {
    // Rings at the same place (a seam for sharp normals) make no faces.
    if (profile[r][0] == profile[r + 1][0] && profile[r][1] == profile[r + 1][1]) continue;
    for (std::uint32_t s = 0; s < static_cast<std::uint32_t>(slices); ++s) {
      const std::uint32_t a = base + r * ring + s, b = a + 1, c = a + ring, d = c + 1;
      // Counter-clockwise seen from outside.
      if (profile[r][0] > 0) mesh.index.insert(mesh.index.end(), {a, b, d});
      if (profile[r + 1][0] > 0) mesh.index.insert(mesh.index.end(), {a, d, c});
    }
  }
}

TriMesh sphere_mesh(double radius, double half_length, int slices, int stacks) {
  // A capsule with half_length 0 is a sphere.
  std::vector<std::array<double, 4>> profile;
  const int half = std::max(2, stacks / 2);
  for (int k = 0; k <= half; ++k) {  // bottom cap, from the pole up to the equator
    const double a = -kPi / 2 + (kPi / 2) * k / half;
    profile.push_back({radius * std::cos(a), -half_length + radius * std::sin(a), std::cos(a), std::sin(a)});
  }
  for (int k = (half_length > 0 ? 0 : 1); k <= half; ++k) {  // top cap, from the equator
    const double a = (kPi / 2) * k / half;
    profile.push_back({radius * std::cos(a), half_length + radius * std::sin(a), std::cos(a), std::sin(a)});
  }
  TriMesh mesh;
  lathe(mesh, profile, slices);
  return mesh;
}

TriMesh cylinder_mesh(double radius, double half_length, int slices) {
  TriMesh mesh;
  lathe(mesh, {{0, -half_length, 0, -1}, {radius, -half_length, 0, -1}, {radius, -half_length, 1, 0},
               {radius, half_length, 1, 0}, {radius, half_length, 0, 1}, {0, half_length, 0, 1}},
        slices);
  return mesh;
}

TriMesh box_mesh(const double* s) {
  TriMesh mesh;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto base = static_cast<std::uint32_t>(mesh.position.size());
      for (int k = 0; k < 4; ++k) {
        Vec3 p{}, n{};
        p[static_cast<std::size_t>(axis)] = sign * s[axis];
        p[static_cast<std::size_t>(u)] = ((k == 1 || k == 2) ? 1 : -1) * s[u];
        p[static_cast<std::size_t>(v)] = (k >= 2 ? 1 : -1) * s[v];
        n[static_cast<std::size_t>(axis)] = sign;
        mesh.position.push_back(p);
        mesh.normal.push_back(n);
      }
      // (u, v) corners -,- / +,- / +,+ / -,+ ; u x v = +axis, so counter-clockwise for +.
      if (sign > 0) mesh.index.insert(mesh.index.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
      else mesh.index.insert(mesh.index.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    }
  }
  return mesh;
}

// The mesh of geom g in its body's frame (MuJoCo axes), or an empty mesh for types not
// exported (planes, height fields, meshes).
TriMesh geom_mesh(const mjModel* m, int g, const GltfOptions& o) {
  const double* s = m->geom_size + 3 * g;
  TriMesh mesh;
  switch (m->geom_type[g]) {
    case mjGEOM_CAPSULE: mesh = sphere_mesh(s[0], s[1], o.slices, o.stacks); break;
    case mjGEOM_SPHERE: mesh = sphere_mesh(s[0], 0.0, o.slices, o.stacks); break;
    case mjGEOM_ELLIPSOID: {
      mesh = sphere_mesh(1.0, 0.0, o.slices, o.stacks);
      for (std::size_t k = 0; k < mesh.position.size(); ++k) {
        Vec3& p = mesh.position[k];
        Vec3& n = mesh.normal[k];
        for (int i = 0; i < 3; ++i) {
          p[static_cast<std::size_t>(i)] *= s[i];
          n[static_cast<std::size_t>(i)] /= s[i];
        }
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (double& c : n) c /= len;
      }
      break;
    }
    case mjGEOM_CYLINDER: mesh = cylinder_mesh(s[0], s[1], o.slices); break;
    case mjGEOM_BOX: mesh = box_mesh(s); break;
    default: return mesh;
  }
  // Into the body frame: p' = pos + R p, n' = R n.
  double r[9];
  mju_quat2Mat(r, m->geom_quat + 4 * g);
  const double* pos = m->geom_pos + 3 * g;
  for (std::size_t k = 0; k < mesh.position.size(); ++k) {
    const Vec3 p = mesh.position[k], n = mesh.normal[k];
    for (int i = 0; i < 3; ++i) {
      mesh.position[k][static_cast<std::size_t>(i)] = pos[i] + r[3 * i] * p[0] + r[3 * i + 1] * p[1] + r[3 * i + 2] * p[2];
      mesh.normal[k][static_cast<std::size_t>(i)] = r[3 * i] * n[0] + r[3 * i + 1] * n[1] + r[3 * i + 2] * n[2];
    }
  }
  return mesh;
}

bool visible(const mjModel* m, int g) {
  if (m->geom_group[g] > 2 || m->geom_type[g] == mjGEOM_PLANE) return false;
  return !(m->geom_rgba[4 * g + 3] == 0.0f && m->geom_matid[g] < 0);
}

// Appends bytes to the one buffer, each view starting on a 4-byte boundary.
class Writer {
 public:
  explicit Writer(tinygltf::Model& model) : model_(model) {
    model_.buffers.resize(1);
  }

  int view(const void* bytes, std::size_t size, int target) {
    auto& data = model_.buffers[0].data;
    while (data.size() % 4) data.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = data.size();
    v.byteLength = size;
    v.target = target;
    const auto* b = static_cast<const unsigned char*>(bytes);
    data.insert(data.end(), b, b + size);
    model_.bufferViews.push_back(v);
    return static_cast<int>(model_.bufferViews.size()) - 1;
  }

  // A float accessor of `type` (TINYGLTF_TYPE_VEC3, ...) with `width` floats per element.
  int floats(const std::vector<float>& values, int width, int type, int target, bool bounds) {
    tinygltf::Accessor a;
    a.bufferView = view(values.data(), values.size() * sizeof(float), target);
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.count = values.size() / static_cast<std::size_t>(width);
    a.type = type;
    if (bounds) {
      a.minValues.assign(static_cast<std::size_t>(width), INFINITY);
      a.maxValues.assign(static_cast<std::size_t>(width), -INFINITY);
      for (std::size_t k = 0; k < values.size(); ++k) {
        const std::size_t c = k % static_cast<std::size_t>(width);
        a.minValues[c] = std::min(a.minValues[c], static_cast<double>(values[k]));
        a.maxValues[c] = std::max(a.maxValues[c], static_cast<double>(values[k]));
      }
    }
    model_.accessors.push_back(a);
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  // An unsigned short accessor (JOINTS_0), `width` per element.
  int ushorts(const std::vector<std::uint16_t>& values, int width, int type) {
    tinygltf::Accessor a;
    a.bufferView = view(values.data(), values.size() * 2, TINYGLTF_TARGET_ARRAY_BUFFER);
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    a.count = values.size() / static_cast<std::size_t>(width);
    a.type = type;
    model_.accessors.push_back(a);
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  int indices(const std::vector<std::uint32_t>& index, std::size_t vertices) {
    tinygltf::Accessor a;
    if (vertices <= 65535) {
      std::vector<std::uint16_t> small(index.begin(), index.end());
      a.bufferView = view(small.data(), small.size() * 2, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
      a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    } else {
      a.bufferView = view(index.data(), index.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
      a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    }
    a.count = index.size();
    a.type = TINYGLTF_TYPE_SCALAR;
    model_.accessors.push_back(a);
    return static_cast<int>(model_.accessors.size()) - 1;
  }

 private:
  tinygltf::Model& model_;
};

std::string body_name(const mjModel* m, int b) {
  const char* raw = mj_id2name(m, mjOBJ_BODY, b);
  return raw && *raw ? raw : "body" + std::to_string(b);
}

// The humanoid bone each body of the human characters (assets/characters/human2d.xml,
// human3d.xml) stands for, named as Unity's Humanoid avatar and Godot's
// SkeletonProfileHumanoid name them, so that retargeting tools can map the skeleton
// (docs/guide/engines.md). Used only for a model whose first body is "pelvis".
const std::map<std::string, std::string>& humanoid_bones() {
  static const std::map<std::string, std::string> bones = {
      {"pelvis", "Hips"},          {"abdomen", "Spine"},         {"torso", "Spine"},
      {"chest", "Chest"},          {"neck", "Neck"},             {"head", "Head"},
      {"upperarm_l", "LeftUpperArm"}, {"forearm_l", "LeftLowerArm"}, {"hand_l", "LeftHand"},
      {"upperarm_r", "RightUpperArm"}, {"forearm_r", "RightLowerArm"}, {"hand_r", "RightHand"},
      {"thigh_l", "LeftUpperLeg"}, {"shin_l", "LeftLowerLeg"},  {"foot_l", "LeftFoot"},
      {"thigh_r", "RightUpperLeg"}, {"shin_r", "RightLowerLeg"}, {"foot_r", "RightFoot"}};
  return bones;
}

// MuJoCo's 3x3 rotation (row-major) in glTF axes: C R C^T with C (x, y, z) -> (x, z, -y).
std::array<double, 9> rotation_to_gltf(const double* r) {
  const int row[3] = {0, 2, 1};
  const double sign[3] = {1, 1, -1};
  std::array<double, 9> out{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[static_cast<std::size_t>(3 * i + j)] = sign[i] * sign[j] * r[3 * row[i] + row[j]];
  return out;
}

}  // namespace

double side_by_side_spacing(const std::vector<GltfMotion>& motions) {
  double widest = 0;
  for (const GltfMotion& motion : motions) {
    if (!motion.model) continue;
    const mjModel* m = motion.model;
    std::unique_ptr<mjData, DataDeleter> d(mj_makeData(m));
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& qpos : motion.frames) {
      if (static_cast<int>(qpos.size()) != m->nq) continue;
      std::copy(qpos.begin(), qpos.end(), d->qpos);
      mj_kinematics(m, d.get());
      for (int g = 0; g < m->ngeom; ++g) {
        if (m->geom_bodyid[g] == 0 || !visible(m, g)) continue;
        lo = std::min(lo, d->geom_xpos[3 * g + 1] - m->geom_rbound[g]);
        hi = std::max(hi, d->geom_xpos[3 * g + 1] + m->geom_rbound[g]);
      }
    }
    if (hi > lo) widest = std::max(widest, hi - lo);
  }
  return widest + 0.5;
}

void write_glb(const std::filesystem::path& path, const std::vector<GltfMotion>& motions,
               const GltfOptions& options) {
  if (!(options.fps > 0)) throw std::invalid_argument("write_glb: fps must be > 0");
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "diverse " DIVERSE_VERSION;
  Writer writer(model);
  tinygltf::Scene scene;
  scene.name = "motions";
  tinygltf::Animation animation;
  animation.name = "motion";
  const bool several = motions.size() > 1;

  for (const GltfMotion& motion : motions) {
    const mjModel* m = motion.model;
    if (m == nullptr || motion.frames.empty())
      throw std::invalid_argument("write_glb: motion " + motion.name + " has no model or no frames");
    for (const auto& qpos : motion.frames)
      if (static_cast<int>(qpos.size()) != m->nq)
        throw std::invalid_argument("write_glb: " + motion.name + ": qpos of size " +
                                    std::to_string(qpos.size()) + ", model nq " + std::to_string(m->nq));
    const std::string prefix = several ? motion.name + " " : "";

    // Materials: one per distinct colour of this model.
    std::map<std::array<float, 4>, int> materials;
    auto material = [&](int g) {
      const float* c = m->geom_matid[g] >= 0 ? m->mat_rgba + 4 * m->geom_matid[g] : m->geom_rgba + 4 * g;
      const std::array<float, 4> key{c[0], c[1], c[2], c[3]};
      auto it = materials.find(key);
      if (it != materials.end()) return it->second;
      tinygltf::Material mat;
      char name[64];
      std::snprintf(name, sizeof name, "rgba %.3g %.3g %.3g %.3g", c[0], c[1], c[2], c[3]);
      mat.name = name;
      mat.pbrMetallicRoughness.baseColorFactor = {linear(c[0]), linear(c[1]), linear(c[2]), c[3]};
      mat.pbrMetallicRoughness.metallicFactor = 0.0;
      mat.pbrMetallicRoughness.roughnessFactor = 0.6;
      if (c[3] < 1.0f) mat.alphaMode = "BLEND";
      model.materials.push_back(mat);
      const int index = static_cast<int>(model.materials.size()) - 1;
      materials[key] = index;
      return index;
    };
    // A body's mesh: one primitive per visible geom; -1 if it has none.
    auto body_mesh = [&](int b, const std::string& name) {
      tinygltf::Mesh mesh;
      mesh.name = name;
      for (int g = 0; g < m->ngeom; ++g) {
        if (m->geom_bodyid[g] != b || !visible(m, g)) continue;
        const TriMesh tri = geom_mesh(m, g, options);
        if (tri.index.empty()) continue;
        std::vector<float> pos, nrm;
        for (std::size_t k = 0; k < tri.position.size(); ++k) {
          for (double v : to_gltf(tri.position[k].data())) pos.push_back(static_cast<float>(v));
          for (double v : to_gltf(tri.normal[k].data())) nrm.push_back(static_cast<float>(v));
        }
        tinygltf::Primitive p;
        p.attributes["POSITION"] = writer.floats(pos, 3, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
        p.attributes["NORMAL"] = writer.floats(nrm, 3, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, false);
        p.indices = writer.indices(tri.index, tri.position.size());
        p.material = material(g);
        p.mode = TINYGLTF_MODE_TRIANGLES;
        mesh.primitives.push_back(p);
      }
      if (mesh.primitives.empty()) return -1;
      model.meshes.push_back(mesh);
      return static_cast<int>(model.meshes.size()) - 1;
    };

    // The skinned character: one mesh of every body's geoms at the bind pose (the model's
    // qpos0), each vertex bound to its body's joint with weight 1 (rigid skinning).
    auto skinned_mesh = [&](const std::string& name, int* bound_joints) {
      std::unique_ptr<mjData, DataDeleter> bind(mj_makeData(m));
      mj_kinematics(m, bind.get());
      tinygltf::Mesh mesh;
      mesh.name = name;
      *bound_joints = 0;
      for (int g = 0; g < m->ngeom; ++g) {
        const int b = m->geom_bodyid[g];
        if (b == 0 || !visible(m, g)) continue;
        const TriMesh tri = geom_mesh(m, g, options);
        if (tri.index.empty()) continue;
        const double* x = bind->xpos + 3 * b;
        const double* r = bind->xmat + 9 * b;
        std::vector<float> pos, nrm, weights;
        std::vector<std::uint16_t> joints;
        for (std::size_t k = 0; k < tri.position.size(); ++k) {
          const Vec3& p = tri.position[k];
          const Vec3& n = tri.normal[k];
          double wp[3], wn[3];
          for (int i = 0; i < 3; ++i) {
            wp[i] = x[i] + r[3 * i] * p[0] + r[3 * i + 1] * p[1] + r[3 * i + 2] * p[2];
            wn[i] = r[3 * i] * n[0] + r[3 * i + 1] * n[1] + r[3 * i + 2] * n[2];
          }
          for (double v : to_gltf(wp)) pos.push_back(static_cast<float>(v));
          for (double v : to_gltf(wn)) nrm.push_back(static_cast<float>(v));
          // Joint b - 1 of the skin (its joints are bodies 1..nbody-1); unused slots 0.
          joints.insert(joints.end(), {static_cast<std::uint16_t>(b - 1), 0, 0, 0});
          weights.insert(weights.end(), {1.0f, 0.0f, 0.0f, 0.0f});
        }
        tinygltf::Primitive p;
        p.attributes["POSITION"] = writer.floats(pos, 3, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
        p.attributes["NORMAL"] = writer.floats(nrm, 3, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, false);
        p.attributes["JOINTS_0"] = writer.ushorts(joints, 4, TINYGLTF_TYPE_VEC4);
        p.attributes["WEIGHTS_0"] = writer.floats(weights, 4, TINYGLTF_TYPE_VEC4, TINYGLTF_TARGET_ARRAY_BUFFER, false);
        p.indices = writer.indices(tri.index, tri.position.size());
        p.material = material(g);
        p.mode = TINYGLTF_MODE_TRIANGLES;
        mesh.primitives.push_back(p);
      }
      // Inverse bind matrices: the inverse of every body's world transform at the bind
      // pose (glTF axes), column-major: [R^T, -R^T x; 0 0 0 1].
      std::vector<float> ibm;
      for (int b = 1; b < m->nbody; ++b) {
        const std::array<double, 9> r = rotation_to_gltf(bind->xmat + 9 * b);
        const Vec3 x = to_gltf(bind->xpos + 3 * b);
        double t[3];
        for (int i = 0; i < 3; ++i) t[i] = -(r[static_cast<std::size_t>(i)] * x[0] + r[static_cast<std::size_t>(3 + i)] * x[1] +
                                             r[static_cast<std::size_t>(6 + i)] * x[2]);
        // Column j of R^T is row j of R.
        for (int j = 0; j < 3; ++j) {
          for (int i = 0; i < 3; ++i) ibm.push_back(static_cast<float>(r[static_cast<std::size_t>(3 * j + i)]));
          ibm.push_back(0.0f);
        }
        ibm.insert(ibm.end(), {static_cast<float>(t[0]), static_cast<float>(t[1]), static_cast<float>(t[2]), 1.0f});
      }
      *bound_joints = writer.floats(ibm, 16, TINYGLTF_TYPE_MAT4, 0, false);
      if (mesh.primitives.empty()) return -1;
      model.meshes.push_back(mesh);
      return static_cast<int>(model.meshes.size()) - 1;
    };

    // The motion's node, placed by its offset.
    tinygltf::Node top;
    top.name = motion.name.empty() ? "motion" : motion.name;
    const Vec3 offset = to_gltf(motion.offset.data());
    if (offset[0] != 0 || offset[1] != 0 || offset[2] != 0) top.translation = {offset[0], offset[1], offset[2]};
    model.nodes.push_back(top);
    const int top_index = static_cast<int>(model.nodes.size()) - 1;
    scene.nodes.push_back(top_index);

    // Scene objects (world body geoms): one static node.
    if (const int mesh = body_mesh(0, prefix + "scene"); mesh >= 0) {
      tinygltf::Node objects;
      objects.name = prefix + "scene";
      objects.mesh = mesh;
      model.nodes.push_back(objects);
      model.nodes[static_cast<std::size_t>(top_index)].children.push_back(static_cast<int>(model.nodes.size()) - 1);
    }

    // Body nodes, parents before children (MuJoCo's body order).
    std::vector<int> node_of(static_cast<std::size_t>(m->nbody), -1);
    node_of[0] = top_index;
    const bool human = m->nbody > 1 && body_name(m, 1) == "pelvis";
    for (int b = 1; b < m->nbody; ++b) {
      tinygltf::Node node;
      node.name = prefix + body_name(m, b);
      if (!options.skinned) node.mesh = body_mesh(b, node.name);
      if (const auto bone = humanoid_bones().find(body_name(m, b)); human && bone != humanoid_bones().end())
        node.extras = tinygltf::Value(tinygltf::Value::Object{{"humanoid_bone", tinygltf::Value(bone->second)}});
      model.nodes.push_back(node);
      node_of[static_cast<std::size_t>(b)] = static_cast<int>(model.nodes.size()) - 1;
      model.nodes[static_cast<std::size_t>(node_of[static_cast<std::size_t>(m->body_parentid[b])])]
          .children.push_back(node_of[static_cast<std::size_t>(b)]);
    }

    // The skin over the body nodes and its mesh, a node of the scene's root (a skinned
    // mesh's own transform is ignored; the joints place it).
    if (options.skinned && m->nbody > 1) {
      int ibm = -1;
      const std::string name = (motion.name.empty() ? std::string("motion") : motion.name) + " body";
      const int mesh = skinned_mesh(name, &ibm);
      tinygltf::Skin skin;
      skin.name = name;
      skin.inverseBindMatrices = ibm;
      skin.skeleton = top_index;
      for (int b = 1; b < m->nbody; ++b) skin.joints.push_back(node_of[static_cast<std::size_t>(b)]);
      model.skins.push_back(skin);
      if (mesh >= 0) {
        tinygltf::Node node;
        node.name = name;
        node.mesh = mesh;
        node.skin = static_cast<int>(model.skins.size()) - 1;
        model.nodes.push_back(node);
        scene.nodes.push_back(static_cast<int>(model.nodes.size()) - 1);
      }
    }

    // Each body's pose in its parent at every frame.
    const std::size_t frames = motion.frames.size();
    std::vector<std::vector<float>> rotation(static_cast<std::size_t>(m->nbody)),
        translation(static_cast<std::size_t>(m->nbody));
    std::unique_ptr<mjData, DataDeleter> d(mj_makeData(m));
    for (const auto& qpos : motion.frames) {
      std::copy(qpos.begin(), qpos.end(), d->qpos);
      mj_kinematics(m, d.get());
      for (int b = 1; b < m->nbody; ++b) {
        const int parent = m->body_parentid[b];
        double q[4], t[3], inv[4], dp[3];
        // q = parent^-1 * body; t = parent^-1 (x_body - x_parent).
        mju_negQuat(inv, d->xquat + 4 * parent);
        mju_mulQuat(q, inv, d->xquat + 4 * b);
        mju_sub3(dp, d->xpos + 3 * b, d->xpos + 3 * parent);
        mju_rotVecQuat(t, dp, inv);
        for (double v : quat_to_gltf_xyzw(q)) rotation[static_cast<std::size_t>(b)].push_back(static_cast<float>(v));
        for (double v : to_gltf(t)) translation[static_cast<std::size_t>(b)].push_back(static_cast<float>(v));
      }
    }
    std::vector<float> times(frames);
    for (std::size_t k = 0; k < frames; ++k) times[k] = static_cast<float>(static_cast<double>(k) / options.fps);
    const int input = writer.floats(times, 1, TINYGLTF_TYPE_SCALAR, 0, true);
    auto channel = [&](int node, const char* path_name, const std::vector<float>& values, int type, int width) {
      tinygltf::AnimationSampler sampler;
      sampler.input = input;
      sampler.output = writer.floats(values, width, type, 0, false);
      sampler.interpolation = "LINEAR";
      animation.samplers.push_back(sampler);
      tinygltf::AnimationChannel c;
      c.sampler = static_cast<int>(animation.samplers.size()) - 1;
      c.target_node = node;
      c.target_path = path_name;
      animation.channels.push_back(c);
    };
    for (int b = 1; b < m->nbody; ++b) {
      const auto ub = static_cast<std::size_t>(b);
      tinygltf::Node& node = model.nodes[static_cast<std::size_t>(node_of[ub])];
      const auto& t = translation[ub];
      const auto& r = rotation[ub];
      node.translation = {t[0], t[1], t[2]};
      node.rotation = {r[0], r[1], r[2], r[3]};
      bool moves = false;
      for (std::size_t k = 3; k < t.size() && !moves; ++k) moves = std::abs(t[k] - t[k % 3]) > 1e-7f;
      if (moves) channel(node_of[ub], "translation", t, TINYGLTF_TYPE_VEC3, 3);
      bool turns = false;
      for (std::size_t k = 4; k < r.size() && !turns; ++k) turns = r[k] != r[k % 4];
      if (turns || frames == 1) channel(node_of[ub], "rotation", r, TINYGLTF_TYPE_VEC4, 4);
    }
  }
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  if (!animation.channels.empty()) model.animations.push_back(animation);

  std::error_code made;
  std::filesystem::create_directories(path.has_parent_path() ? path.parent_path() : std::filesystem::path("."), made);
  if (made) throw UserError(path.string() + ": cannot be written (" + made.message() + ")");
  const std::filesystem::path tmp = path.string() + ".tmp";
  tinygltf::TinyGLTF gltf;
  if (!gltf.WriteGltfSceneToFile(&model, tmp.string(), true, true, false, true))
    throw UserError(path.string() + ": cannot be written");
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) throw UserError(path.string() + ": cannot be written (" + error.message() + ")");
}

}  // namespace diverse
