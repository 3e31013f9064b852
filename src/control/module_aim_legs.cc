#include "control/module_aim_legs.h"

#include <algorithm>
#include <cmath>

namespace diverse {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
// Rodrigues: u turned by `angle` about the unit axis a.
Vec3 turn(const Vec3& a, double angle, const Vec3& u) {
  const double c = std::cos(angle), s = std::sin(angle);
  return add(add(scale(u, c), scale(cross(a, u), s)), scale(a, dot(a, u) * (1 - c)));
}
Vec3 in_frame(const std::array<double, 4>& inv, const std::array<double, 3>& v) {
  Vec3 out;
  mju_rotVecQuat(out.data(), v.data(), inv.data());
  return out;
}

double clamp_to_range(const CharacterJoint& j, double q) {
  if (std::isfinite(j.lower) && std::isfinite(j.upper)) return std::clamp(q, j.lower, j.upper);
  return q;
}

bool on_feet(const Character& body, const JointGroup& g) {
  for (int k : g.joints) {
    const int b = body.joints[static_cast<size_t>(k)].body;
    if (b != body.feet[0] && b != body.feet[1]) return false;
  }
  return true;
}

}  // namespace

HipAngles hip_angles_for(const Vec3& leg, const Vec3& pitch_axis, const Vec3& roll_axis, bool has_roll,
                         const Vec3& direction) {
  HipAngles out;
  const Vec3& u = leg;
  const Vec3& w = direction;
  const Vec3& ap = pitch_axis;
  // Roll first (the pitch, applied after it, keeps every component along its own axis):
  // make u's component along the pitch axis equal w's. With a the roll axis (orthogonal to
  // the pitch axis), (R(a, r) u) . ap = A cos r + B sin r, A = u . ap, B = (a x u) . ap.
  if (has_roll) {
    const Vec3& ar = roll_axis;
    const double A = dot(u, ap), B = dot(cross(ar, u), ap), c = dot(w, ap);
    const double R = std::hypot(A, B);
    if (R > 1e-12) {
      const double base = std::atan2(B, A), spread = std::acos(std::clamp(c / R, -1.0, 1.0));
      const double r1 = std::remainder(base + spread, 2 * M_PI), r2 = std::remainder(base - spread, 2 * M_PI);
      out.roll = std::fabs(r1) < std::fabs(r2) ? r1 : r2;
    }
  }
  const Vec3 u1 = has_roll ? turn(roll_axis, out.roll, u) : u;
  // Then the pitch: the turn about the pitch axis from u1 to w, in the plane normal to it.
  const Vec3 a_perp = sub(u1, scale(ap, dot(u1, ap)));
  const Vec3 b_perp = sub(w, scale(ap, dot(w, ap)));
  out.pitch = std::atan2(dot(ap, cross(a_perp, b_perp)), dot(a_perp, b_perp));
  return out;
}

AimLegsModule::AimLegsModule(const ModuleSettings& settings, const Character& body)
    : body_(body),
      offset_{settings.get("offset_left", 0), settings.get("offset_right", 0)},
      velocity_gain_{settings.get("velocity_gain_left", 0), settings.get("velocity_gain_right", 0)} {
  const int hip = body.find_group(JointRole::kHip, JointPlane::kSagittal);
  const int hip_roll = body.find_group(JointRole::kHip, JointPlane::kCoronal);
  for (size_t g = 0; g < body.groups.size() && foot_group_ < 0; ++g) {
    const JointGroup& group = body.groups[g];
    if (group.plane == JointPlane::kSagittal && group.joints.size() == 2 && on_feet(body, group)) foot_group_ = static_cast<int>(g);
  }
  for (size_t s = 0; s < 2; ++s) {
    LegGeometry& leg = legs_[s];
    leg.hip_pitch = body.groups[static_cast<size_t>(hip)].joints[s];
    if (hip_roll >= 0 && body.groups[static_cast<size_t>(hip_roll)].joints.size() == 2) {
      leg.hip_roll = body.groups[static_cast<size_t>(hip_roll)].joints[s];
    }
  }
}

void AimLegsModule::reset(const mjModel* m, const mjData* d, SkillState& s) {
  (void)s;  // the state's fields are not needed before the first phase
  const double* q0 = m->qpos0 + body_.root_qpos + 3;
  root0_inv_ = {q0[0], -q0[1], -q0[2], -q0[3]};
  mju_normalize4(root0_inv_.data());
  {  // the yaw of the root's x axis
    double R[9];
    mju_quat2Mat(R, d->xquat + 4 * body_.root_body);
    heading_ = std::atan2(R[3], R[0]);
  }
  // Leg geometry at qpos0, in the root's frame.
  double middle = 0;
  std::array<Vec3, 2> foot_point{};
  for (size_t side = 0; side < 2; ++side) {
    LegGeometry& leg = legs_[side];
    const CharacterJoint& hip = body_.joints[static_cast<size_t>(leg.hip_pitch)];
    const int foot_joint = body_.groups[static_cast<size_t>(foot_group_)].joints[side];
    const CharacterJoint& foot = body_.joints[static_cast<size_t>(foot_joint)];
    leg.pitch0 = m->qpos0[hip.qpos];
    leg.pitch_axis = in_frame(root0_inv_, hip.axis0);
    if (leg.hip_roll >= 0) {
      const CharacterJoint& roll = body_.joints[static_cast<size_t>(leg.hip_roll)];
      leg.roll0 = m->qpos0[roll.qpos];
      leg.roll_axis = in_frame(root0_inv_, roll.axis0);
    }
    // The joints strictly between the hip's body and the foot's, top down (chain() runs
    // from the joint's body up to the root).
    const std::vector<int>& chain = body_.chain(foot_joint);
    leg.middle.clear();
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const CharacterJoint& j = body_.joints[static_cast<size_t>(*it)];
      if (j.body != hip.body && j.body != foot.body) leg.middle.push_back(*it);
    }
    leg.middle0.clear();
    leg.axes.clear();
    leg.segments.clear();
    Vec3 from = hip.anchor0;
    for (int k : leg.middle) {
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      leg.middle0.push_back(m->qpos0[j.qpos]);
      leg.axes.push_back(in_frame(root0_inv_, j.axis0));
      leg.segments.push_back(in_frame(root0_inv_, sub(j.anchor0, from)));
      from = j.anchor0;
    }
    leg.segments.push_back(in_frame(root0_inv_, sub(foot.anchor0, from)));
    foot_point[side] = in_frame(root0_inv_, foot.anchor0);
    middle += 0.5 * foot_point[side][1];
  }
  for (size_t side = 0; side < 2; ++side) legs_[side].lateral = foot_point[side][1] - middle;
}

void AimLegsModule::set_targets(const mjModel* m, const mjData* d, SkillState& s) {
  (void)m;
  // Blended in while the root is within 60 degrees of upright.
  const int root = body_.root_body;
  double up0[3];
  const double z[3] = {0, 0, 1};
  mju_rotVecQuat(up0, z, root0_inv_.data());
  double up[3];
  mju_mulMatVec(up, d->xmat + 9 * root, up0, 3, 3);
  const double w = std::clamp((up[2] - 0.5) / 0.5, 0.0, 1.0);
  if (w <= 0) return;
  std::vector<double>& target = s.target;
  std::array<double, 4> hips{};
  for (size_t side = 0; side < 2; ++side) {
    const LegGeometry& leg = legs_[side];
    hips[2 * side] = target[static_cast<size_t>(leg.hip_pitch)];
    hips[2 * side + 1] = leg.hip_roll >= 0 ? target[static_cast<size_t>(leg.hip_roll)] : 0;
  }
  // Where the COM comes down on its ballistic path to the height it took off at (raised by
  // the landing surface's height): where the feet meet the ground.
  const double g = s.gravity;
  const double height = std::max(s.com[2] - s.takeoff_com_z - s.landing_height, 0.0);
  const double vz = s.com_vel[2];
  const double t_cross = (vz + std::sqrt(vz * vz + 2 * g * height)) / g;
  const double f[2] = {std::cos(heading_), std::sin(heading_)};
  const double lat[2] = {-f[1], f[0]};
  std::array<std::array<double, 2>, 2> goals{};
  for (size_t side = 0; side < 2; ++side) {
    for (size_t i = 0; i < 2; ++i) {
      goals[side][i] = s.com[i] + s.com_vel[i] * t_cross + offset_[side] * f[i] + velocity_gain_[side] * s.com_vel[i] +
                       legs_[side].lateral * lat[i];
    }
  }
  point_legs(d, goals, target);
  for (size_t side = 0; side < 2; ++side) {
    const LegGeometry& leg = legs_[side];
    double& pitch = target[static_cast<size_t>(leg.hip_pitch)];
    pitch = (1 - w) * hips[2 * side] + w * pitch;
    if (leg.hip_roll >= 0) {
      double& roll = target[static_cast<size_t>(leg.hip_roll)];
      roll = (1 - w) * hips[2 * side + 1] + w * roll;
    }
  }
}

void AimLegsModule::point_legs(const mjData* d, const std::array<std::array<double, 2>, 2>& goals,
                               std::vector<double>& targets) const {
  const int root = body_.root_body;
  std::array<double, 4> root_inv{d->xquat[4 * root], -d->xquat[4 * root + 1], -d->xquat[4 * root + 2],
                                 -d->xquat[4 * root + 3]};
  for (size_t s = 0; s < 2; ++s) {
    const LegGeometry& leg = legs_[s];
    const double* goal = goals[s].data();
    // The leg (hip to foot joint) with the joints between at their targets, in the root's
    // frame with the hip at its reference angles: s0 + R1 (s1 + R2 (s2 + ...)).
    Vec3 v = leg.segments.back();
    for (size_t i = leg.middle.size(); i-- > 0;) {
      const double q = targets[static_cast<size_t>(leg.middle[i])];
      v = add(leg.segments[i], turn(leg.axes[i], q - leg.middle0[i], v));
    }
    const double length = std::sqrt(dot(v, v));
    if (length < 1e-6) continue;
    const CharacterJoint& hip = body_.joints[static_cast<size_t>(leg.hip_pitch)];
    const double* p = d->xanchor + 3 * hip.joint;
    const double dx = goal[0] - p[0], dy = goal[1] - p[1];
    const double reach = std::min(std::hypot(dx, dy), 0.9 * length);
    const double k = std::hypot(dx, dy) > 1e-9 ? reach / std::hypot(dx, dy) : 0;
    const Vec3 r_world{dx * k, dy * k, -std::sqrt(length * length - reach * reach)};
    Vec3 w;
    mju_rotVecQuat(w.data(), r_world.data(), root_inv.data());
    w = scale(w, 1 / length);
    const HipAngles a = hip_angles_for(scale(v, 1 / length), leg.pitch_axis, leg.roll_axis, leg.hip_roll >= 0, w);
    targets[static_cast<size_t>(leg.hip_pitch)] = clamp_to_range(hip, leg.pitch0 + a.pitch);
    if (leg.hip_roll >= 0) {
      const CharacterJoint& r = body_.joints[static_cast<size_t>(leg.hip_roll)];
      targets[static_cast<size_t>(leg.hip_roll)] = clamp_to_range(r, leg.roll0 + a.roll);
    }
  }
}

}  // namespace diverse
