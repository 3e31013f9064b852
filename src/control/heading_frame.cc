#include "control/heading_frame.h"

#include <cmath>

namespace diverse {
namespace {

double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

}  // namespace

StandingFrames standing_frames(const mjModel* m, int root_body) {
  StandingFrames s;
  const int nb = m->nbody;
  s.quat.assign(static_cast<size_t>(nb), {1, 0, 0, 0});
  std::vector<std::array<double, 3>> pos(static_cast<size_t>(nb), {0, 0, 0});
  double com[3] = {0, 0, 0};
  for (int b = 1; b < nb; ++b) {
    const size_t bb = static_cast<size_t>(b), parent = static_cast<size_t>(m->body_parentid[b]);
    double R[9], off[3];
    mju_quat2Mat(R, s.quat[parent].data());
    mju_mulMatVec(off, R, m->body_pos + 3 * b, 3, 3);
    for (size_t i = 0; i < 3; ++i) pos[bb][i] = pos[parent][i] + off[i];
    mju_mulQuat(s.quat[bb].data(), s.quat[parent].data(), m->body_quat + 4 * b);
    if (m->body_rootid[b] != root_body) continue;
    double Rb[9], ci[3];
    mju_quat2Mat(Rb, s.quat[bb].data());
    mju_mulMatVec(ci, Rb, m->body_ipos + 3 * b, 3, 3);
    for (size_t i = 0; i < 3; ++i) com[i] += m->body_mass[b] * (pos[bb][i] + ci[i]);
  }
  s.root = s.quat[static_cast<size_t>(root_body)];
  s.root_heading = heading_of(s.root.data());
  s.mass = m->body_subtreemass[root_body];
  s.com_height = com[2] / s.mass;
  return s;
}

double heading_of(const double* q) {
  double R[9];
  mju_quat2Mat(R, q);
  return std::atan2(R[3], R[0]);
}

double root_heading(const mjData* d, int root_body, const StandingFrames& s) {
  double q[4], unturn[4];
  mju_negQuat(unturn, s.root.data());
  mju_mulQuat(q, d->xquat + 4 * root_body, unturn);
  return heading_of(q) + 0.0;
}

void rotation_error(const double* target, const double* q, double* e) {
  double inv[4], dq[4];
  mju_negQuat(inv, q);
  mju_mulQuat(dq, target, inv);
  if (dq[0] < 0) {
    for (double& c : dq) c = -c;
  }
  mju_quat2Vel(e, dq, 1.0);
}

HeadingLink heading_link(const Character& body, const mjModel* m, const StandingFrames& s, int link_body) {
  HeadingLink t;
  t.body = link_body;
  double R[9];
  mju_quat2Mat(R, s.quat[static_cast<size_t>(link_body)].data());
  for (int k = 0; k < body.dof(); ++k) {
    const CharacterJoint& j = body.joints[static_cast<size_t>(k)];
    if (j.body != link_body) continue;
    t.joints.push_back(k);
    std::array<double, 3> a{};
    mju_mulMatVec(a.data(), R, m->jnt_axis + 3 * j.joint, 3, 3);
    t.axes.push_back(a);
  }
  t.standing = s.quat[static_cast<size_t>(link_body)];
  return t;
}

void heading_link_target(const HeadingLink& link, double h, const double* angles, double* quat) {
  double q[4] = {std::cos(h / 2), 0, 0, std::sin(h / 2)};
  for (size_t i = 0; i < link.joints.size(); ++i) {
    double r[4], next[4];
    mju_axisAngle2Quat(r, link.axes[i].data(), angles[i]);
    mju_mulQuat(next, q, r);
    mju_copy4(q, next);
  }
  mju_mulQuat(quat, q, link.standing.data());
}

void heading_root_target(const StandingFrames& s, double heading, double pitch, double roll, double* quat) {
  const double pitch_axis[3] = {0, -1, 0}, roll_axis[3] = {1, 0, 0};
  double yaw[4] = {std::cos(heading / 2), 0, 0, std::sin(heading / 2)};
  double p[4], r[4], a[4], b[4];
  mju_axisAngle2Quat(p, pitch_axis, pitch);
  mju_axisAngle2Quat(r, roll_axis, roll);
  mju_mulQuat(a, yaw, p);
  mju_mulQuat(b, a, r);
  // The standing orientation without its heading (the heading frame replaces it).
  double unturn[4] = {std::cos(-s.root_heading / 2), 0, 0, std::sin(-s.root_heading / 2)};
  double level[4];
  mju_mulQuat(level, unturn, s.root.data());
  mju_mulQuat(quat, b, level);
}

LegLayout leg_layout(const Character& body) {
  LegLayout l;
  const size_t n = body.joints.size();
  l.leg_of.assign(n, -1);
  l.hip.assign(n, 0);
  l.foot.assign(n, 0);
  for (size_t k = 0; k < n; ++k) {
    const int s = body.foot_of_body_[static_cast<size_t>(body.joints[k].body)];
    if (s < 0) continue;
    // The foot's own hinges (and any below it) and everything on the path to the root.
    l.foot[k] = 1;
    for (int c : body.chain(static_cast<int>(k))) l.leg_of[static_cast<size_t>(c)] = s;
  }
  for (size_t k = 0; k < n; ++k) {
    // On a child of the root: every joint between it and the root is on its own body.
    bool on_root_child = true;
    for (int c : body.chain(static_cast<int>(k))) on_root_child = on_root_child && body.joints[static_cast<size_t>(c)].body == body.joints[k].body;
    if (on_root_child) l.root_children.push_back(static_cast<int>(k));
    l.hip[k] = l.leg_of[k] >= 0 && on_root_child;
  }
  for (size_t k = 0; k < n; ++k) {
    const int leg = l.leg_of[k];
    if (leg >= 0 && !l.hip[k] && !l.foot[k]) l.middle[static_cast<size_t>(leg)].push_back(static_cast<int>(k));
  }
  return l;
}

double gravity_torque(const mjModel* m, const mjData* d, const CharacterJoint& j, double gravity) {
  const double* a = d->xaxis + 3 * j.joint;
  const double* p = d->xanchor + 3 * j.joint;
  const double* c = d->subtree_com + 3 * j.body;
  const double r[3] = {c[0] - p[0], c[1] - p[1], c[2] - p[2]};
  const double f[3] = {0, 0, m->body_subtreemass[j.body] * gravity};
  double rf[3];
  mju_cross(rf, r, f);
  return dot3(a, rf);
}

}  // namespace diverse
