#include "character/character.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "core/error.h"
#include "core/text_file.h"
#include "core/toml_reader.h"
#include "physics/model.h"

namespace diverse {
namespace fs = std::filesystem;
namespace {

constexpr const char* kRoleNames[] = {"hip",   "knee",  "ankle", "toe",  "shoulder", "elbow",
                                      "wrist", "waist", "neck",  "tail", "other"};
constexpr int kNumRoles = static_cast<int>(sizeof kRoleNames / sizeof kRoleNames[0]);
constexpr const char* kPlaneNames[] = {"sagittal", "coronal", "transverse"};

std::string role_list() {
  std::string s;
  for (const char* r : kRoleNames) s += std::string(s.empty() ? "" : ", ") + r;
  return s;
}

JointRole parse_role(const TomlReader& r) {
  const std::string v = r.string("role");
  for (int i = 0; i < kNumRoles; ++i)
    if (v == kRoleNames[i]) return static_cast<JointRole>(i);
  r.fail("role", "expected one of " + role_list() + ", got \"" + v + "\"");
}

JointPlane parse_plane(const TomlReader& r) {
  const std::string v = r.string("plane", "sagittal");
  for (int i = 0; i < 3; ++i)
    if (v == kPlaneNames[i]) return static_cast<JointPlane>(i);
  r.fail("plane", "expected \"sagittal\", \"coronal\" or \"transverse\", got \"" + v + "\"");
}

std::string resolve_beside(const std::string& file, const std::string& relative) {
  fs::path p(relative);
  if (p.is_absolute()) return p.lexically_normal().string();
  return (fs::path(file).parent_path() / p).lexically_normal().string();
}

void read_root(const TomlReader& r, CharacterSpec& spec) {
  const std::string kind = r.string("kind");
  spec.root_body = r.string("body");
  spec.root_wja = r.number("wja", 0, 100, 1.0);
  if (kind == "planar") {
    r.only({"kind", "body", "x", "z", "pitch", "wja"});
    spec.root = RootKind::kPlanar;
    spec.root_x = r.string("x");
    spec.root_z = r.string("z");
    spec.root_pitch = r.string("pitch");
  } else if (kind == "free") {
    r.only({"kind", "body", "joint", "wja"});
    spec.root = RootKind::kFree;
    spec.root_free = r.string("joint");
  } else {
    r.fail("kind", "expected \"planar\" or \"free\", got \"" + kind + "\"");
  }
}

void read_groups(const TomlReader& r, CharacterSpec& spec) {
  const auto tables = r.tables("groups", true);
  if (tables.empty()) r.fail("groups", "expected at least one [[groups]] entry");
  std::set<std::string> names, joints;
  for (size_t i = 0; i < tables.size(); ++i) {
    TomlReader g = r.element("groups", i, *tables[i]);
    g.only({"name", "role", "plane", "joints", "wja", "kp", "kd"});
    JointGroupSpec group;
    group.name = g.string("name");
    if (group.name.empty()) g.fail("name", "expected a non-empty string");
    if (!names.insert(group.name).second) g.fail("name", "expected a name no other group has, got \"" + group.name + "\" twice");
    group.role = parse_role(g);
    group.plane = parse_plane(g);
    group.joints = g.strings("joints", 1);
    if (group.joints.size() > 2) g.fail("joints", "expected one joint (centre) or two (left, right), got " + std::to_string(group.joints.size()));
    for (const std::string& j : group.joints) {
      if (!joints.insert(j).second) g.fail("joints", "expected each joint in one group only, got \"" + j + "\" again");
    }
    group.wja = g.number("wja", 0, 100);
    group.kp = g.number("kp", 0, 1e5);
    group.kd = g.number("kd", 0, 1e4);
    spec.groups.push_back(std::move(group));
  }
}

void read_shape(const TomlReader& r, CharacterSpec& spec) {
  const toml::table* t = r.table("shape", false);
  if (t == nullptr) return;
  TomlReader s = r.sub("shape", *t);
  s.only({"min_link_length", "parameters"});
  spec.shape_min_link_length = s.number("min_link_length", 0.001, 1.0, spec.shape_min_link_length);
  const auto tables = s.tables("parameters", true);
  if (tables.empty()) s.fail("parameters", "expected at least one [[shape.parameters]] entry");
  std::set<std::string> names, links;
  for (size_t i = 0; i < tables.size(); ++i) {
    TomlReader p = s.element("parameters", i, *tables[i]);
    p.only({"name", "links", "min", "max"});
    ShapeGroupSpec group;
    group.name = p.string("name");
    if (group.name.empty()) p.fail("name", "expected a non-empty string");
    if (!names.insert(group.name).second) p.fail("name", "expected a name no other parameter has, got \"" + group.name + "\" twice");
    group.links = p.strings("links", 1);
    for (const std::string& l : group.links) {
      if (!links.insert(l).second) p.fail("links", "expected each link in one shape parameter only, got \"" + l + "\" again");
    }
    group.min = p.number("min", 0.05, 1.0);
    group.max = p.number("max", 1.0, 20.0);
    spec.shape.push_back(std::move(group));
  }
}

// ---------------------------------------------------------------------------------------

class Binder {
 public:
  Binder(const CharacterSpec& spec, const mjModel* m, std::string origin)
      : spec_(spec), m_(m), origin_(std::move(origin)) {}

  [[noreturn]] void file_error(const std::string& field, const std::string& what) const {
    throw_field_error(spec_.file, field, what);
  }
  [[noreturn]] void model_error(const std::string& field, const std::string& what) const {
    throw_field_error(origin_, field, what);
  }

  int joint(const std::string& field, const std::string& name) const {
    const int id = mj_name2id(m_, mjOBJ_JOINT, name.c_str());
    if (id < 0) file_error(field, "expected a joint of the model " + origin_ + ", but it has no joint '" + name + "'");
    return id;
  }
  int body(const std::string& field, const std::string& name) const {
    const int id = mj_name2id(m_, mjOBJ_BODY, name.c_str());
    if (id < 0) file_error(field, "expected a body of the model " + origin_ + ", but it has no body '" + name + "'");
    return id;
  }
  std::string joint_name(int id) const {
    const char* n = mj_id2name(m_, mjOBJ_JOINT, id);
    return n ? n : "#" + std::to_string(id);
  }
  std::string body_name(int id) const {
    const char* n = mj_id2name(m_, mjOBJ_BODY, id);
    return n ? n : "#" + std::to_string(id);
  }

 private:
  const CharacterSpec& spec_;
  const mjModel* m_;
  std::string origin_;
};


}  // namespace

const char* to_string(JointRole role) { return kRoleNames[static_cast<int>(role)]; }
const char* to_string(JointPlane plane) { return kPlaneNames[static_cast<int>(plane)]; }
const char* to_string(RootKind kind) { return kind == RootKind::kPlanar ? "planar" : "free"; }

CharacterSpec load_character_file(const std::string& path) {
  if (!fs::is_regular_file(path)) throw UserError(path + ": cannot read the character file");
  const toml::table root = parse_toml_file(path, "character");
  CharacterSpec spec;
  spec.file = path;
  TomlReader r(path, root, "");
  r.only({"name", "description", "model", "root", "groups", "feet", "hands", "shape"});
  spec.name = r.string("name");
  if (spec.name.empty()) r.fail("name", "expected a non-empty string");
  spec.description = r.string("description", "");
  spec.model = resolve_beside(path, r.string("model"));
  if (!fs::is_regular_file(spec.model)) {
    r.fail("model", "expected an existing MJCF file (relative to the character file), but " + spec.model +
                        " does not exist");
  }
  read_root(r.sub("root", *r.table("root", true)), spec);
  read_groups(r, spec);
  {
    TomlReader f = r.sub("feet", *r.table("feet", true));
    f.only({"bodies"});
    const auto feet = f.strings("bodies");
    if (feet.size() != 2) f.fail("bodies", "expected two foot bodies (left, right)");
    spec.feet = {feet[0], feet[1]};
  }
  if (const toml::table* t = r.table("hands", false)) {
    TomlReader h = r.sub("hands", *t);
    h.only({"bodies"});
    spec.hands = h.strings("bodies");
    if (!spec.hands.empty() && spec.hands.size() != 2) {
      h.fail("bodies", "expected no hands ([]) or two hand bodies (left, right)");
    }
  }
  read_shape(r, spec);
  return spec;
}

std::string resolve_character_file(const std::string& path) {
  fs::path p(path);
  if (p.extension() == ".xml") {
    fs::path toml = p;
    toml.replace_extension(".toml");
    if (!fs::is_regular_file(toml)) {
      throw UserError(path + ": expected a character file beside the model (" + toml.string() +
                      "); docs/reference/character-file.md says how to write one");
    }
    return toml.lexically_normal().string();
  }
  if (!fs::is_regular_file(p)) {
    read_text_file(path, "character");  // throws, naming why (missing, a directory, ...)
    throw UserError(path + ": cannot read the character file");
  }
  return p.lexically_normal().string();
}

int Character::find_group(const std::string& name) const {
  for (size_t i = 0; i < groups.size(); ++i)
    if (groups[i].name == name) return static_cast<int>(i);
  return -1;
}

int Character::find_group(JointRole role, JointPlane plane) const {
  for (size_t i = 0; i < groups.size(); ++i)
    if (groups[i].role == role && groups[i].plane == plane) return static_cast<int>(i);
  return -1;
}

bool Character::is_foot_geom(const mjModel* m, int geom, int* foot) const {
  const int b = m->geom_bodyid[geom];
  const int f = (b >= 0 && b < static_cast<int>(foot_of_body_.size())) ? foot_of_body_[static_cast<size_t>(b)] : -1;
  if (foot != nullptr) *foot = f;
  return f >= 0;
}

bool Character::is_link(const mjModel* m, int body) const {
  return body > 0 && body < m->nbody && m->body_rootid[body] == root_body;
}

double Character::child_pitch(const double* qpos, int j) const {
  double pitch = qpos[root_pitch_qpos];
  for (int k : chain_[static_cast<size_t>(j)]) pitch += qpos[joints[static_cast<size_t>(k)].qpos];
  return pitch;
}

double Character::child_pitch_rate(const double* qvel, int j) const {
  double rate = qvel[root_pitch_dof];
  for (int k : chain_[static_cast<size_t>(j)]) rate += qvel[joints[static_cast<size_t>(k)].dof];
  return rate;
}

Character bind_character(std::shared_ptr<const CharacterSpec> spec_ptr, const mjModel* m,
                         const std::string& origin) {
  const CharacterSpec& spec = *spec_ptr;
  Binder b(spec, m, origin);
  Character c;
  c.spec = spec_ptr;
  c.root = spec.root;

  // Root.
  c.root_body = b.body("root.body", spec.root_body);
  if (m->body_parentid[c.root_body] != 0) {
    b.file_error("root.body", "expected a body directly in the worldbody, but '" + spec.root_body +
                                  "' is inside '" + b.body_name(m->body_parentid[c.root_body]) + "'");
  }
  auto root_joint = [&](const char* field, const std::string& name, int type, const char* what) {
    const int j = b.joint(std::string("root.") + field, name);
    if (m->jnt_type[j] != type) b.file_error(std::string("root.") + field, std::string("expected '") + name + "' to be " + what);
    if (m->jnt_bodyid[j] != c.root_body) {
      b.file_error(std::string("root.") + field, "expected '" + name + "' in the root body '" + spec.root_body + "'");
    }
    c.root_joints.push_back(j);
    return j;
  };
  if (spec.root == RootKind::kPlanar) {
    const int x = root_joint("x", spec.root_x, mjJNT_SLIDE, "a slide joint along x");
    const int z = root_joint("z", spec.root_z, mjJNT_SLIDE, "a slide joint along z");
    const int p = root_joint("pitch", spec.root_pitch, mjJNT_HINGE, "a hinge about -y");
    auto axis_is = [&](int j, double ax, double ay, double az) {
      const double* a = m->jnt_axis + 3 * j;
      return std::fabs(a[0] - ax) < 1e-9 && std::fabs(a[1] - ay) < 1e-9 && std::fabs(a[2] - az) < 1e-9;
    };
    if (!axis_is(x, 1, 0, 0)) b.file_error("root.x", "expected the slide '" + spec.root_x + "' along x (axis 1 0 0)");
    if (!axis_is(z, 0, 0, 1)) b.file_error("root.z", "expected the slide '" + spec.root_z + "' along z (axis 0 0 1)");
    if (!axis_is(p, 0, -1, 0)) b.file_error("root.pitch", "expected the hinge '" + spec.root_pitch + "' about -y (axis 0 -1 0)");
    c.root_x_qpos = m->jnt_qposadr[x];
    c.root_z_qpos = m->jnt_qposadr[z];
    c.root_pitch_qpos = m->jnt_qposadr[p];
    c.root_x_dof = m->jnt_dofadr[x];
    c.root_z_dof = m->jnt_dofadr[z];
    c.root_pitch_dof = m->jnt_dofadr[p];
  } else {
    const int f = root_joint("joint", spec.root_free, mjJNT_FREE, "a free joint");
    c.root_qpos = m->jnt_qposadr[f];
    c.root_dof = m->jnt_dofadr[f];
  }

  // Links: every body under the root body.
  for (int body = 1; body < m->nbody; ++body) {
    if (m->body_rootid[body] != c.root_body) continue;
    c.links.push_back(body);
    c.total_mass += m->body_mass[body];
    if (!(m->body_mass[body] >= 1e-6)) {
      b.model_error("body '" + b.body_name(body) + "'", "expected a link with mass > 0 (it has " +
                                                          num(m->body_mass[body]) + " kg)");
    }
  }

  // Actuators: motors with gear 1 and a symmetric force limit, one per non-root joint.
  std::vector<int> actuator_of(static_cast<size_t>(m->njnt), -1);
  for (int a = 0; a < m->nu; ++a) {
    const char* an = mj_id2name(m, mjOBJ_ACTUATOR, a);
    const std::string field = std::string("actuator '") + (an ? an : "#" + std::to_string(a)) + "'";
    if (m->actuator_trntype[a] != mjTRN_JOINT) b.model_error(field, "expected an actuator on a joint");
    const int j = m->actuator_trnid[2 * a];
    if (std::find(c.root_joints.begin(), c.root_joints.end(), j) != c.root_joints.end()) {
      b.model_error(field, "expected no actuator on the root joint '" + b.joint_name(j) +
                               "' (the root is unactuated: all motion comes from joint torques)");
    }
    const double* gear = m->actuator_gear + 6 * a;
    if (gear[0] != 1 || gear[1] != 0 || gear[2] != 0 || gear[3] != 0 || gear[4] != 0 || gear[5] != 0) {
      b.model_error(field, "expected gear=\"1\" (ctrl is the joint torque in Nm), got " + num(gear[0]));
    }
    if (m->actuator_gaintype[a] != mjGAIN_FIXED || m->actuator_gainprm[mjNGAIN * a] != 1 ||
        m->actuator_biastype[a] != mjBIAS_NONE || m->actuator_dyntype[a] != mjDYN_NONE) {
      b.model_error(field, "expected a <motor> (gain 1, no bias, no dynamics)");
    }
    const double lo = m->actuator_forcerange[2 * a], hi = m->actuator_forcerange[2 * a + 1];
    if (!m->actuator_forcelimited[a] || !(hi > 0) || lo != -hi) {
      b.model_error(field, "expected a torque limit: forcelimited=\"true\" forcerange=\"-L L\" with L > 0");
    }
    if (actuator_of[static_cast<size_t>(j)] >= 0) {
      b.model_error(field, "expected one actuator per joint, but joint '" + b.joint_name(j) + "' has two");
    }
    actuator_of[static_cast<size_t>(j)] = a;
  }

  // Groups and their joints.
  std::vector<int> joint_index(static_cast<size_t>(m->njnt), -1);
  for (size_t gi = 0; gi < spec.groups.size(); ++gi) {
    const JointGroupSpec& gs = spec.groups[gi];
    const std::string field = "groups[" + std::to_string(gi) + "].joints";
    JointGroup g;
    g.name = gs.name;
    g.role = gs.role;
    g.plane = gs.plane;
    g.wja = gs.wja;
    g.kp = gs.kp;
    g.kd = gs.kd;
    for (size_t s = 0; s < gs.joints.size(); ++s) {
      CharacterJoint cj;
      cj.name = gs.joints[s];
      cj.group = static_cast<int>(gi);
      cj.side = gs.joints.size() == 1 ? Side::kCenter : static_cast<Side>(s);
      cj.joint = b.joint(field, cj.name);
      if (m->jnt_type[cj.joint] != mjJNT_HINGE) b.file_error(field, "expected '" + cj.name + "' to be a hinge joint");
      if (m->body_rootid[m->jnt_bodyid[cj.joint]] != c.root_body || m->jnt_bodyid[cj.joint] == c.root_body) {
        b.file_error(field, "expected '" + cj.name + "' in a body below the root body '" + spec.root_body + "'");
      }
      if (spec.root == RootKind::kPlanar) {
        const double* a = m->jnt_axis + 3 * cj.joint;
        if (std::fabs(a[0]) > 1e-9 || std::fabs(a[1] + 1) > 1e-9 || std::fabs(a[2]) > 1e-9) {
          b.file_error(field, "expected '" + cj.name + "' to turn about -y (axis 0 -1 0), as every hinge of a planar character does");
        }
      }
      cj.qpos = m->jnt_qposadr[cj.joint];
      cj.dof = m->jnt_dofadr[cj.joint];
      cj.body = m->jnt_bodyid[cj.joint];
      cj.actuator = actuator_of[static_cast<size_t>(cj.joint)];
      if (cj.actuator < 0) {
        b.model_error("joint '" + cj.name + "'", "expected a <motor> with forcelimited=\"true\" forcerange=\"-L L\" driving it (its torque limit)");
      }
      cj.torque_limit = m->actuator_forcerange[2 * cj.actuator + 1];
      if (m->jnt_limited[cj.joint]) {
        cj.lower = m->jnt_range[2 * cj.joint];
        cj.upper = m->jnt_range[2 * cj.joint + 1];
      } else {
        cj.lower = -INFINITY;
        cj.upper = INFINITY;
      }
      joint_index[static_cast<size_t>(cj.joint)] = static_cast<int>(c.joints.size());
      g.joints.push_back(static_cast<int>(c.joints.size()));
      c.joints.push_back(cj);
    }
    if (g.joints.size() == 2) {
      const CharacterJoint& l = c.joints[static_cast<size_t>(g.joints[0])];
      const CharacterJoint& r = c.joints[static_cast<size_t>(g.joints[1])];
      if (m->jnt_limited[l.joint] != m->jnt_limited[r.joint] ||
          (m->jnt_limited[l.joint] && (std::fabs(l.lower - r.lower) > 1e-9 || std::fabs(l.upper - r.upper) > 1e-9))) {
        b.file_error(field, "expected the left/right pair '" + l.name + "', '" + r.name +
                                "' to have the same range, got [" + num(l.lower) + ", " + num(l.upper) +
                                "] and [" + num(r.lower) + ", " + num(r.upper) + "]");
      }
      if (l.torque_limit != r.torque_limit) {
        b.file_error(field, "expected the left/right pair '" + l.name + "', '" + r.name +
                                "' to have the same torque limit, got " + num(l.torque_limit) + " and " +
                                num(r.torque_limit) + " Nm");
      }
    }
    c.groups.push_back(std::move(g));
  }

  // Every joint of the character is the root or in a group.
  for (int j = 0; j < m->njnt; ++j) {
    if (m->body_rootid[m->jnt_bodyid[j]] != c.root_body) continue;
    if (std::find(c.root_joints.begin(), c.root_joints.end(), j) != c.root_joints.end()) continue;
    if (joint_index[static_cast<size_t>(j)] < 0) {
      b.file_error("groups", "expected every joint of the model in a group, but '" + b.joint_name(j) + "' is in none");
    }
  }
  for (int j = 0; j < m->njnt; ++j) {
    if (actuator_of[static_cast<size_t>(j)] >= 0 && joint_index[static_cast<size_t>(j)] < 0 &&
        std::find(c.root_joints.begin(), c.root_joints.end(), j) == c.root_joints.end()) {
      b.model_error("joint '" + b.joint_name(j) + "'", "expected an actuated joint to belong to the character");
    }
  }

  // Feet and hands.
  c.foot_of_body_.assign(static_cast<size_t>(m->nbody), -1);
  for (int s = 0; s < 2; ++s) {
    const std::string field = "feet.bodies";
    c.feet[static_cast<size_t>(s)] = b.body(field, spec.feet[static_cast<size_t>(s)]);
    if (!c.is_link(m, c.feet[static_cast<size_t>(s)])) b.file_error(field, "expected a body of the character, got '" + spec.feet[static_cast<size_t>(s)] + "'");
  }
  if (c.feet[0] == c.feet[1]) b.file_error("feet.bodies", "expected two different foot bodies");
  for (int body = 1; body < m->nbody; ++body) {
    for (int p = body; p > 0; p = m->body_parentid[p]) {
      if (p == c.feet[0]) c.foot_of_body_[static_cast<size_t>(body)] = 0;
      if (p == c.feet[1]) c.foot_of_body_[static_cast<size_t>(body)] = 1;
      if (c.foot_of_body_[static_cast<size_t>(body)] >= 0) break;
    }
  }
  for (const std::string& h : spec.hands) {
    const int id = b.body("hands.bodies", h);
    if (!c.is_link(m, id)) b.file_error("hands.bodies", "expected a body of the character, got '" + h + "'");
    c.hands.push_back(id);
  }

  // Chains (joints from the root down to each joint, inclusive).
  c.chain_.resize(c.joints.size());
  for (size_t i = 0; i < c.joints.size(); ++i) {
    std::vector<int> path;
    for (int body = c.joints[i].body; body != c.root_body && body > 0; body = m->body_parentid[body]) {
      for (int j = m->body_jntadr[body]; j >= 0 && j < m->body_jntadr[body] + m->body_jntnum[body]; ++j) {
        if (joint_index[static_cast<size_t>(j)] >= 0) path.push_back(joint_index[static_cast<size_t>(j)]);
      }
    }
    c.chain_[i] = path;
  }

  // Standing height at the model's reference pose.
  mjData* d = mj_makeData(m);
  mj_kinematics(m, d);
  double low = INFINITY, high = -INFINITY;
  for (int g = 0; g < m->ngeom; ++g) {
    if (!c.is_link(m, m->geom_bodyid[g])) continue;
    double lo = 0, hi = 0;
    geom_z_extent(m, d, g, &lo, &hi);
    low = std::min(low, lo);
    high = std::max(high, hi);
  }
  for (CharacterJoint& j : c.joints) {
    for (int k = 0; k < 3; ++k) {
      j.anchor0[static_cast<size_t>(k)] = d->xanchor[3 * j.joint + k];
      j.axis0[static_cast<size_t>(k)] = d->xaxis[3 * j.joint + k];
    }
    j.standing = m->qpos0[j.qpos];
  }
  mj_deleteData(d);
  c.height = std::isfinite(high - low) ? high - low : 0;
  return c;
}

}  // namespace diverse
