#include "io/bvh.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "core/error.h"
#include "io/files.h"

namespace diverse {
namespace {

using Mat3 = std::array<double, 9>;  // row-major
using Vec3 = std::array<double, 3>;

constexpr double kDegree = std::numbers::pi / 180.0;
const Mat3 kIdentity{1, 0, 0, 0, 1, 0, 0, 0, 1};

Mat3 multiply(const Mat3& a, const Mat3& b) {
  Mat3 c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[3 * i + j] += a[3 * i + k] * b[3 * k + j];
  return c;
}

Mat3 transpose(const Mat3& a) {
  return {a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8]};
}

Vec3 rotate(const Mat3& a, const Vec3& v) {
  return {a[0] * v[0] + a[1] * v[1] + a[2] * v[2], a[3] * v[0] + a[4] * v[1] + a[5] * v[2],
          a[6] * v[0] + a[7] * v[1] + a[8] * v[2]};
}

// Rotation by `degrees` about axis 0 (X), 1 (Y) or 2 (Z).
Mat3 axis_rotation(int axis, double degrees) {
  const double c = std::cos(degrees * kDegree), s = std::sin(degrees * kDegree);
  switch (axis) {
    case 0: return {1, 0, 0, 0, c, -s, 0, s, c};
    case 1: return {c, 0, s, 0, 1, 0, -s, 0, c};
    default: return {c, -s, 0, s, c, 0, 0, 0, 1};
  }
}

// (X, Y, Z)_bvh = C (x, y, z)_mujoco with C = [[1,0,0],[0,0,1],[0,-1,0]]; rotations map as
// C R C^T.
const Mat3 kMujocoToBvh{1, 0, 0, 0, 0, 1, 0, -1, 0};

Mat3 rotation_to_bvh(const Mat3& r) {
  return multiply(multiply(kMujocoToBvh, r), transpose(kMujocoToBvh));
}

// Intrinsic Z, X, Y angles (degrees) of R = Rz(a) Rx(b) Ry(c):
//   R = [[ca cc - sa sb sc, -sa cb, ca sc + sa sb cc],
//        [sa cc + ca sb sc,  ca cb, sa sc - ca sb cc],
//        [-cb sc,            sb,    cb cc]]
Vec3 euler_zxy(const Mat3& r) {
  const double sb = std::clamp(r[7], -1.0, 1.0);
  const double b = std::asin(sb);
  double a = 0, c = 0;
  if (std::abs(sb) < 1.0 - 1e-12) {
    a = std::atan2(-r[1], r[4]);
    c = std::atan2(-r[6], r[8]);
  } else {
    // Gimbal lock (b = +-90 degrees): only a + c or a - c is defined; put it all in a.
    a = std::atan2(r[3], r[0]);
  }
  return {a / kDegree, b / kDegree, c / kDegree};
}

// The value equal to `angle` modulo 360 degrees that is nearest to `previous`.
double unwrap(double angle, double previous) {
  return angle - 360.0 * std::round((angle - previous) / 360.0);
}

int channel_axis(const std::string& channel) {
  if (channel.size() < 2) return -1;
  const char a = channel[0];
  return a == 'X' ? 0 : a == 'Y' ? 1 : a == 'Z' ? 2 : -1;
}

bool is_position(const std::string& c) {
  return c == "Xposition" || c == "Yposition" || c == "Zposition";
}
bool is_rotation(const std::string& c) {
  return c == "Xrotation" || c == "Yrotation" || c == "Zrotation";
}

std::string number(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.6f", v == 0.0 ? 0.0 : v);  // no "-0.000000"
  return text;
}

// A BVH name must be one token.
std::string joint_name(const mjModel* m, int body) {
  const char* raw = mj_id2name(m, mjOBJ_BODY, body);
  std::string name = raw && *raw ? raw : "body" + std::to_string(body);
  for (char& ch : name)
    if (std::isspace(static_cast<unsigned char>(ch)) || ch == '{' || ch == '}') ch = '_';
  return name;
}

Mat3 quat_to_mat(const double* q) {
  Mat3 r{};
  mju_quat2Mat(r.data(), q);
  return r;
}

// The far end (body frame, m) of a leaf body's first geom, for its End Site.
Vec3 leaf_end(const mjModel* m, int body) {
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_bodyid[g] != body) continue;
    const double* p = m->geom_pos + 3 * g;
    const double* s = m->geom_size + 3 * g;
    const Mat3 r = quat_to_mat(m->geom_quat + 4 * g);
    switch (m->geom_type[g]) {
      case mjGEOM_CAPSULE:
      case mjGEOM_CYLINDER: {
        // The segment's two ends along the geom's z axis; the one farther from the origin.
        const Vec3 axis{r[2] * s[1], r[5] * s[1], r[8] * s[1]};
        const Vec3 a{p[0] + axis[0], p[1] + axis[1], p[2] + axis[2]};
        const Vec3 b{p[0] - axis[0], p[1] - axis[1], p[2] - axis[2]};
        const auto norm2 = [](const Vec3& v) { return v[0] * v[0] + v[1] * v[1] + v[2] * v[2]; };
        return norm2(a) >= norm2(b) ? a : b;
      }
      case mjGEOM_SPHERE:
      case mjGEOM_ELLIPSOID: {
        // Through the centre, away from the origin (up if the sphere is centred on it).
        const double d = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        if (d < 1e-9) return {0, 0, s[0]};
        return {p[0] * (1 + s[0] / d), p[1] * (1 + s[0] / d), p[2] * (1 + s[0] / d)};
      }
      default:
        if (p[0] != 0 || p[1] != 0 || p[2] != 0) return {p[0], p[1], p[2]};
        return {0, 0, s[2] > 0 ? s[2] : 0.05};
    }
  }
  return {0, 0, 0.05};
}

// A body whose every joint is a hinge at the body's origin, in a body frame not rotated
// against its parent's (body_quat the identity), each axis along a BVH axis (+-X, +-Y, +-Z
// after the change of axes), turns exactly as the BVH rotation channels of those axes in
// the joints' order: MuJoCo composes a body's joints in order, each about its axis in the
// frame the joints before it turned (R = R(a1, q1) R(a2, q2)), as a BVH joint composes its
// channels (R = R_first R_second). Such a body gets one channel per hinge; a universal
// joint (pitch then roll) becomes two.
struct HingeChannel {
  int axis = 0;       // 0 X, 1 Y, 2 Z (BVH axes)
  double sign = 1.0;  // +1 if the hinge turns about +axis, -1 about -axis
  int qpos = 0;       // the hinge's qpos address
};

std::vector<HingeChannel> hinge_channels(const mjModel* m, int body) {
  std::vector<HingeChannel> out;
  const int n = m->body_jntnum[body];
  if (n == 0) return out;
  const double* q = m->body_quat + 4 * body;
  if (std::abs(q[0] - 1.0) > 1e-12 || std::abs(q[1]) > 1e-12 || std::abs(q[2]) > 1e-12 ||
      std::abs(q[3]) > 1e-12)
    return out;
  for (int k = 0; k < n; ++k) {
    const int jnt = m->body_jntadr[body] + k;
    if (m->jnt_type[jnt] != mjJNT_HINGE) return {};
    const double* p = m->jnt_pos + 3 * jnt;
    if (std::abs(p[0]) > 1e-12 || std::abs(p[1]) > 1e-12 || std::abs(p[2]) > 1e-12) return {};
    const Vec3 a = mujoco_to_bvh(m->jnt_axis + 3 * jnt);
    HingeChannel h;
    h.axis = -1;
    for (int i = 0; i < 3; ++i) {
      const bool others_zero = std::abs(a[(i + 1) % 3]) < 1e-12 && std::abs(a[(i + 2) % 3]) < 1e-12;
      if (others_zero && std::abs(std::abs(a[i]) - 1.0) < 1e-12) {
        h.axis = i;
        h.sign = a[i] > 0 ? 1.0 : -1.0;
      }
    }
    if (h.axis < 0) return {};
    h.qpos = m->jnt_qposadr[jnt];
    out.push_back(h);
  }
  return out;
}

// Tokens with their line numbers.
struct Token {
  std::string text;
  int line = 0;
};

class Reader {
 public:
  Reader(const std::string& text, std::string origin) : origin_(std::move(origin)) {
    std::istringstream lines(text);
    std::string line;
    for (int n = 1; std::getline(lines, line); ++n) {
      std::istringstream words(line);
      for (std::string w; words >> w;) tokens_.push_back({w, n});
      last_line_ = n;
    }
  }

  bool done() const { return pos_ >= tokens_.size(); }
  const Token& peek() const { return tokens_[pos_]; }
  Token next(const std::string& what) {
    if (done()) fail(last_line_, what + " (file ends early)");
    return tokens_[pos_++];
  }
  void expect(const std::string& word) {
    const Token t = next("\"" + word + "\"");
    if (t.text != word) fail(t.line, "\"" + word + "\", found \"" + t.text + "\"");
  }
  double number(const std::string& what) {
    const Token t = next(what);
    try {
      std::size_t used = 0;
      const double v = std::stod(t.text, &used);
      if (used != t.text.size() || !std::isfinite(v)) throw std::invalid_argument("");
      return v;
    } catch (const std::exception&) {
      fail(t.line, what + ", found \"" + t.text + "\"");
    }
  }
  [[noreturn]] void fail(int line, const std::string& expectation) const {
    throw UserError(origin_ + ": line " + std::to_string(line) + ": expected " + expectation);
  }
  std::size_t position() const { return pos_; }
  const std::vector<Token>& tokens() const { return tokens_; }
  int last_line() const { return last_line_; }

 private:
  std::string origin_;
  std::vector<Token> tokens_;
  std::size_t pos_ = 0;
  int last_line_ = 0;
};

void read_joint(Reader& in, Bvh& bvh, int parent) {
  const Token name = in.next("a joint name");
  BvhJoint joint;
  joint.name = name.text;
  joint.parent = parent;
  in.expect("{");
  in.expect("OFFSET");
  for (double& v : joint.offset) v = in.number("an OFFSET value");
  in.expect("CHANNELS");
  const Token count_token = in.next("a channel count");
  int count = 0;
  try {
    count = std::stoi(count_token.text);
  } catch (const std::exception&) {
    count = -1;
  }
  if (count < 0 || count > 6) in.fail(count_token.line, "a channel count of 0 to 6");
  for (int c = 0; c < count; ++c) {
    const Token channel = in.next("a channel name");
    if (!is_position(channel.text) && !is_rotation(channel.text))
      in.fail(channel.line, "a channel name (Xposition ... Zrotation), found \"" + channel.text + "\"");
    joint.channels.push_back(channel.text);
  }
  const int index = static_cast<int>(bvh.joints.size());
  bvh.joints.push_back(joint);
  while (true) {
    const Token t = in.next("JOINT, End Site or \"}\"");
    if (t.text == "}") return;
    if (t.text == "JOINT") {
      read_joint(in, bvh, index);
    } else if (t.text == "End") {
      in.expect("Site");
      in.expect("{");
      in.expect("OFFSET");
      BvhJoint& j = bvh.joints[static_cast<std::size_t>(index)];
      j.has_end_site = true;
      for (double& v : j.end_site) v = in.number("an OFFSET value");
      in.expect("}");
    } else {
      in.fail(t.line, "JOINT, End Site or \"}\", found \"" + t.text + "\"");
    }
  }
}

void write_joint(std::string& out, const Bvh& bvh, int index, int depth) {
  const BvhJoint& j = bvh.joints[static_cast<std::size_t>(index)];
  const std::string pad(static_cast<std::size_t>(depth), '\t');
  out += pad + (j.parent < 0 ? "ROOT " : "JOINT ") + j.name + "\n" + pad + "{\n";
  out += pad + "\tOFFSET " + number(j.offset[0]) + " " + number(j.offset[1]) + " " +
         number(j.offset[2]) + "\n";
  out += pad + "\tCHANNELS " + std::to_string(j.channels.size());
  for (const std::string& c : j.channels) out += " " + c;
  out += "\n";
  for (std::size_t k = 0; k < bvh.joints.size(); ++k)
    if (bvh.joints[k].parent == index) write_joint(out, bvh, static_cast<int>(k), depth + 1);
  if (j.has_end_site) {
    out += pad + "\tEnd Site\n" + pad + "\t{\n" + pad + "\t\tOFFSET " + number(j.end_site[0]) +
           " " + number(j.end_site[1]) + " " + number(j.end_site[2]) + "\n" + pad + "\t}\n";
  }
  out += pad + "}\n";
}

}  // namespace

int Bvh::channel_count() const {
  int n = 0;
  for (const BvhJoint& j : joints) n += static_cast<int>(j.channels.size());
  return n;
}

int Bvh::find(const std::string& name) const {
  for (std::size_t i = 0; i < joints.size(); ++i)
    if (joints[i].name == name) return static_cast<int>(i);
  return -1;
}

std::string bvh_text(const Bvh& bvh) {
  std::string out = "HIERARCHY\n";
  for (std::size_t k = 0; k < bvh.joints.size(); ++k)
    if (bvh.joints[k].parent < 0) write_joint(out, bvh, static_cast<int>(k), 0);
  out += "MOTION\nFrames: " + std::to_string(bvh.frames.size()) + "\n";
  char time[64];
  std::snprintf(time, sizeof time, "%.8f", bvh.frame_time);
  out += std::string("Frame Time: ") + time + "\n";
  for (const auto& frame : bvh.frames) {
    for (std::size_t i = 0; i < frame.size(); ++i) {
      if (i > 0) out += ' ';
      out += number(frame[i]);
    }
    out += '\n';
  }
  return out;
}

Bvh parse_bvh(const std::string& text, const std::string& origin) {
  Reader in(text, origin);
  Bvh bvh;
  in.expect("HIERARCHY");
  in.expect("ROOT");
  read_joint(in, bvh, -1);
  in.expect("MOTION");
  in.expect("Frames:");
  const Token frames_token = in.next("a frame count");
  long frames = -1;
  try {
    frames = std::stol(frames_token.text);
  } catch (const std::exception&) {
  }
  if (frames < 0) in.fail(frames_token.line, "a frame count >= 0, found \"" + frames_token.text + "\"");
  in.expect("Frame");
  in.expect("Time:");
  bvh.frame_time = in.number("a frame time in seconds");
  if (!(bvh.frame_time > 0)) in.fail(in.tokens()[in.position() - 1].line, "a frame time > 0");

  // One line of values per frame.
  const std::size_t channels = static_cast<std::size_t>(bvh.channel_count());
  while (!in.done()) {
    const int line = in.peek().line;
    std::vector<double> values;
    while (!in.done() && in.peek().line == line) values.push_back(in.number("a channel value"));
    if (values.size() != channels)
      in.fail(line, std::to_string(channels) + " channel values, found " + std::to_string(values.size()));
    bvh.frames.push_back(std::move(values));
  }
  if (static_cast<long>(bvh.frames.size()) != frames)
    in.fail(in.last_line(), std::to_string(frames) + " frames (as declared), found " +
                                std::to_string(bvh.frames.size()));
  return bvh;
}

void write_bvh(const std::filesystem::path& path, const Bvh& bvh) {
  write_file_atomic(path, bvh_text(bvh));
}

Bvh read_bvh(const std::filesystem::path& path) {
  return parse_bvh(read_file(path), path.string());
}

BvhPose bvh_pose(const Bvh& bvh, int frame) {
  if (frame < 0 || frame >= bvh.frame_count())
    throw std::out_of_range("bvh_pose: frame " + std::to_string(frame) + " of " +
                            std::to_string(bvh.frame_count()));
  const std::vector<double>& values = bvh.frames[static_cast<std::size_t>(frame)];
  BvhPose pose;
  pose.position.resize(bvh.joints.size());
  pose.rotation.resize(bvh.joints.size());
  std::size_t v = 0;
  for (std::size_t i = 0; i < bvh.joints.size(); ++i) {
    const BvhJoint& j = bvh.joints[i];
    Vec3 translation = j.offset;
    Mat3 local = kIdentity;
    for (const std::string& c : j.channels) {
      const double value = values[v++];
      if (is_position(c)) {
        translation[static_cast<std::size_t>(channel_axis(c))] += value;
      } else {
        local = multiply(local, axis_rotation(channel_axis(c), value));
      }
    }
    if (j.parent < 0) {
      pose.position[i] = translation;
      pose.rotation[i] = local;
    } else {
      const auto p = static_cast<std::size_t>(j.parent);
      const Vec3 d = rotate(pose.rotation[p], translation);
      pose.position[i] = {pose.position[p][0] + d[0], pose.position[p][1] + d[1],
                          pose.position[p][2] + d[2]};
      pose.rotation[i] = multiply(pose.rotation[p], local);
    }
  }
  return pose;
}

std::array<double, 3> mujoco_to_bvh(const double* v) { return {v[0], v[2], -v[1]}; }

Bvh bvh_from_model(const mjModel* m, std::span<const std::vector<double>> qpos_frames,
                   double fps, std::vector<int>* body_of_joint) {
  if (!(fps > 0)) throw std::invalid_argument("bvh_from_model: fps must be > 0");

  // The root: the one child of the world body whose subtree has degrees of freedom.
  std::vector<int> dofs(static_cast<std::size_t>(m->nbody), 0);
  for (int b = m->nbody - 1; b > 0; --b) {
    dofs[static_cast<std::size_t>(b)] += m->body_jntnum[b];
    if (m->body_parentid[b] > 0) dofs[static_cast<std::size_t>(m->body_parentid[b])] += dofs[static_cast<std::size_t>(b)];
  }
  int root = -1;
  for (int b = 1; b < m->nbody; ++b) {
    if (m->body_parentid[b] != 0 || dofs[static_cast<std::size_t>(b)] == 0) continue;
    if (root >= 0)
      throw UserError("BVH export: the model has more than one moving body tree (" +
                      joint_name(m, root) + ", " + joint_name(m, b) +
                      "); a BVH file has a single root");
    root = b;
  }
  if (root < 0) throw UserError("BVH export: the model has no moving bodies");

  // Joints in depth-first order, children by body id, as the file nests them.
  Bvh bvh;
  bvh.frame_time = 1.0 / fps;
  std::vector<int> bodies;
  std::vector<std::vector<HingeChannel>> hinges;  // per BVH joint; empty: Euler channels
  std::function<void(int, int)> add = [&](int body, int parent) {
    BvhJoint j;
    j.name = joint_name(m, body);
    j.parent = parent;
    j.offset = parent < 0 ? Vec3{0, 0, 0} : mujoco_to_bvh(m->body_pos + 3 * body);
    std::vector<HingeChannel> own = parent < 0 ? std::vector<HingeChannel>{} : hinge_channels(m, body);
    if (parent < 0) j.channels = {"Xposition", "Yposition", "Zposition"};
    if (own.empty()) {
      j.channels.insert(j.channels.end(), {"Zrotation", "Xrotation", "Yrotation"});
    } else {
      for (const HingeChannel& h : own) j.channels.push_back(std::string(1, "XYZ"[h.axis]) + "rotation");
    }
    hinges.push_back(std::move(own));
    const int index = static_cast<int>(bvh.joints.size());
    bvh.joints.push_back(j);
    bodies.push_back(body);
    bool leaf = true;
    for (int c = body + 1; c < m->nbody; ++c) {
      if (m->body_parentid[c] == body) {
        leaf = false;
        add(c, index);
      }
    }
    if (leaf) {
      const Vec3 end = leaf_end(m, body);
      bvh.joints[static_cast<std::size_t>(index)].has_end_site = true;
      bvh.joints[static_cast<std::size_t>(index)].end_site = mujoco_to_bvh(end.data());
    }
  };
  add(root, -1);

  std::unique_ptr<mjData, void (*)(mjData*)> data(mj_makeData(m), mj_deleteData);
  std::vector<double> previous;
  for (const std::vector<double>& qpos : qpos_frames) {
    if (static_cast<int>(qpos.size()) != m->nq)
      throw std::invalid_argument("bvh_from_model: qpos of size " + std::to_string(qpos.size()) +
                                  ", model nq " + std::to_string(m->nq));
    std::copy(qpos.begin(), qpos.end(), data->qpos);
    mj_kinematics(m, data.get());
    std::vector<double> values;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      const int b = bodies[i];
      if (!hinges[i].empty()) {
        // One channel per hinge, in the body's joint order: the hinge's angle from its
        // reference (MuJoCo turns a hinge by qpos - qpos0), signed by its axis.
        for (const HingeChannel& h : hinges[i])
          values.push_back(h.sign * (qpos[static_cast<std::size_t>(h.qpos)] - m->qpos0[h.qpos]) / kDegree);
        continue;
      }
      const Mat3 world = quat_to_mat(data->xquat + 4 * b);
      Mat3 local = world;
      if (bvh.joints[i].parent < 0) {
        const Vec3 p = mujoco_to_bvh(data->xpos + 3 * b);
        values.insert(values.end(), p.begin(), p.end());
      } else {
        const int parent = m->body_parentid[b];
        local = multiply(transpose(quat_to_mat(data->xquat + 4 * parent)), world);
      }
      const Vec3 angles = euler_zxy(rotation_to_bvh(local));
      values.insert(values.end(), angles.begin(), angles.end());
    }
    // Unwrap rotation channels against the previous frame (positions never wrap).
    if (!previous.empty()) {
      std::size_t v = 0;
      for (const BvhJoint& j : bvh.joints)
        for (const std::string& c : j.channels) {
          if (is_rotation(c)) values[v] = unwrap(values[v], previous[v]);
          ++v;
        }
    }
    previous = values;
    bvh.frames.push_back(std::move(values));
  }
  if (body_of_joint) *body_of_joint = bodies;
  return bvh;
}

}  // namespace diverse
