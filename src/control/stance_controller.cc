#include "control/stance_controller.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "core/polygon.h"

namespace diverse {
namespace {

double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// a . ((r) x f)
double axis_moment(const double* a, const double* r, const double* f) {
  double c[3];
  mju_cross(c, r, f);
  return dot3(a, c);
}

// Gravity compensation of one hinge: the torque about its axis that holds up the links it
// carries, a . ((c_sub - p) x m_sub g z), with c_sub and m_sub its subtree's COM and mass.
double gravity_torque(const mjModel* m, const mjData* d, const CharacterJoint& j, double gravity) {
  const double* a = d->xaxis + 3 * j.joint;
  const double* p = d->xanchor + 3 * j.joint;
  const double* c = d->subtree_com + 3 * j.body;
  const double r[3] = {c[0] - p[0], c[1] - p[1], c[2] - p[2]};
  const double f[3] = {0, 0, m->body_subtreemass[j.body] * gravity};
  return axis_moment(a, r, f);
}

// Rotation vector (world frame) of the rotation that takes orientation q to `target`.
void rotation_error(const double* target, const double* q, double* e) {
  double inv[4], dq[4];
  mju_negQuat(inv, q);
  mju_mulQuat(dq, target, inv);
  if (dq[0] < 0) {
    for (double& v : dq) v = -v;
  }
  mju_quat2Vel(e, dq, 1.0);
}

// Heading (yaw about world z) of a body's x axis, from its orientation quaternion.
double yaw_of(const double* quat) {
  double R[9];
  mju_quat2Mat(R, quat);
  return std::atan2(R[3], R[0]);
}

int depth(const mjModel* m, int body) {
  int n = 0;
  for (int b = body; b > 0; b = m->body_parentid[b]) ++n;
  return n;
}

// Scratch data for the constructor's forward kinematics at qpos0, kept per thread and
// reused while the models it serves have the same sizes: a controller is built for
// every rollout, and mj_makeData (which allocates and clears the whole arena, megabytes
// for a 3D character) cost about 3 % of a rollout. mjData's layout depends only on the
// model's sizes, and mj_kinematics and mj_comPos write every value they read back here.
mjData* scratch_data(const mjModel* m) {
  struct Scratch {
    std::array<int, 12> sizes{};
    mjData* d = nullptr;
    ~Scratch() {
      if (d != nullptr) mj_deleteData(d);
    }
  };
  thread_local Scratch scratch;
  const std::array<int, 12> sizes{m->nq,    m->nv,   m->nu,    m->na,     m->nbody, m->njnt,
                                  m->ngeom, m->nsite, m->nmocap, m->nstack, m->njmax, m->nconmax};
  if (scratch.d == nullptr || scratch.sizes != sizes) {
    if (scratch.d != nullptr) mj_deleteData(scratch.d);
    scratch.d = mj_makeData(m);
    scratch.sizes = sizes;
  }
  // What mj_kinematics reads besides qpos: the mocap bodies' poses (mj_resetData's).
  for (int b = 0; b < m->nbody; ++b) {
    const int id = m->body_mocapid[b];
    if (id < 0) continue;
    mju_copy3(scratch.d->mocap_pos + 3 * id, m->body_pos + 3 * b);
    mju_copy4(scratch.d->mocap_quat + 4 * id, m->body_quat + 4 * b);
  }
  return scratch.d;
}

}  // namespace

StanceController::StanceController(const Character& body, const mjModel* m, StanceGains gains)
    : body_(body), gains_(gains) {
  // A planar root (x, z, pitch) works as well: every quantity is taken in the world, and
  // what lies out of the plane (lateral forces, roll and yaw) turns no hinge of the plane.
  const int n = body.dof();
  const int root = body.root_body;
  targets_.resize(static_cast<size_t>(n));
  u_.assign(static_cast<size_t>(n), 0.0);
  kd_.assign(static_cast<size_t>(n), 0.0);
  leg_of_.assign(static_cast<size_t>(n), -1);
  is_hip_.assign(static_cast<size_t>(n), 0);
  std::vector<int> index_of(static_cast<size_t>(m->njnt), -1);
  for (int k = 0; k < n; ++k) {
    const CharacterJoint& j = body.joints[static_cast<size_t>(k)];
    targets_[static_cast<size_t>(k)] = m->qpos0[j.qpos];
    kp_.push_back(body.strength * body.groups[static_cast<size_t>(j.group)].kp);
    kd_gain_.push_back(body.strength * body.groups[static_cast<size_t>(j.group)].kd);
    index_of[static_cast<size_t>(j.joint)] = k;
    if (m->body_parentid[j.body] == root) root_children_.push_back(k);
  }

  // Legs: the hinges from each foot up to the root.
  geom_side_.assign(static_cast<size_t>(m->ngeom), -1);
  for (int s = 0; s < 2; ++s) {
    const int foot = body.feet[static_cast<size_t>(s)];
    Leg& leg = legs_[static_cast<size_t>(s)];
    for (int b = foot; b != root && b > 0; b = m->body_parentid[b]) {
      for (int jj = m->body_jntadr[b]; jj >= 0 && jj < m->body_jntadr[b] + m->body_jntnum[b];
           ++jj) {
        const int k = index_of[static_cast<size_t>(jj)];
        if (k < 0) continue;
        leg.joints.push_back(k);
        leg_of_[static_cast<size_t>(k)] = s;
        if (b == foot) {
          leg.foot.push_back(k);
        }
        if (m->body_parentid[b] == root) {
          leg.hips.push_back(k);
          is_hip_[static_cast<size_t>(k)] = 1;
        }
      }
    }
    for (int g = 0; g < m->ngeom; ++g) {
      for (int b = m->geom_bodyid[g]; b > 0; b = m->body_parentid[b]) {
        if (b == foot) {
          geom_side_[static_cast<size_t>(g)] = s;
          break;
        }
      }
    }
  }

  // The torso: the child of the deepest waist hinge.
  int deepest = -1;
  for (int k = 0; k < n; ++k) {
    const CharacterJoint& j = body.joints[static_cast<size_t>(k)];
    if (body.groups[static_cast<size_t>(j.group)].role != JointRole::kWaist) continue;
    if (deepest < 0 || depth(m, j.body) > depth(m, deepest)) deepest = j.body;
  }
  torso_body_ = deepest;
  for (int k = 0; k < n && deepest >= 0; ++k) {
    const CharacterJoint& j = body.joints[static_cast<size_t>(k)];
    if (j.body == deepest && body.groups[static_cast<size_t>(j.group)].role == JointRole::kWaist) {
      waist_.push_back(k);
    }
  }

  // The standing pose: feet's up vectors, the torso in the root, the COM height.
  mjData* d0 = scratch_data(m);
  mju_copy(d0->qpos, m->qpos0, m->nq);
  mj_kinematics(m, d0);
  mj_comPos(m, d0);
  for (int s = 0; s < 2; ++s) {
    const double* R = d0->xmat + 9 * body.feet[static_cast<size_t>(s)];
    foot_up_[static_cast<size_t>(s)] = {R[6], R[7], R[8]};
  }
  for (int i = 0; i < 4; ++i) root_standing_[static_cast<size_t>(i)] = d0->xquat[4 * root + i];
  if (torso_body_ >= 0) {
    double inv[4];
    mju_negQuat(inv, d0->xquat + 4 * root);
    mju_mulQuat(torso_in_root_.data(), inv, d0->xquat + 4 * torso_body_);
  }
  mass_ = m->body_subtreemass[root];
  gravity_ = -m->opt.gravity[2];
  const double standing_height = d0->subtree_com[3 * root + 2];
  root_kp_ = gains_.root_kp > 0 ? gains_.root_kp : 2 * mass_ * gravity_ * standing_height;
  root_kd_ = gains_.root_kd > 0 ? gains_.root_kd : root_kp_ / 10;
  height_target_ = standing_height;
}

void StanceController::set_targets(std::vector<double> targets) {
  if (targets.size() != targets_.size()) {
    throw std::invalid_argument("StanceController::set_targets: expected one target per joint");
  }
  targets_ = std::move(targets);
}

std::vector<double> StanceController::standing_pose(const mjModel* m) const {
  const int root = body_.root_body;
  std::vector<int> hips, feet;  // sagittal hinges of the hips and of the feet
  for (int s = 0; s < 2; ++s) {
    for (int k : legs_[static_cast<size_t>(s)].hips) {
      if (body_.groups[static_cast<size_t>(body_.joints[static_cast<size_t>(k)].group)].plane ==
          JointPlane::kSagittal)
        hips.push_back(k);
    }
    for (int k : legs_[static_cast<size_t>(s)].foot) {
      if (body_.groups[static_cast<size_t>(body_.joints[static_cast<size_t>(k)].group)].plane ==
          JointPlane::kSagittal)
        feet.push_back(k);
    }
  }
  mjData* d = mj_makeData(m);
  mju_copy(d->qpos, m->qpos0, m->nq);
  mj_kinematics(m, d);
  std::array<std::array<double, 3>, 2> foot0{};
  double centre_x = 0, geoms = 0;
  for (int s = 0; s < 2; ++s) {
    const double* x = d->xpos + 3 * body_.feet[static_cast<size_t>(s)];
    foot0[static_cast<size_t>(s)] = {x[0], x[1], x[2]};
  }
  for (int g = 0; g < m->ngeom; ++g) {
    if (geom_side_[static_cast<size_t>(g)] < 0) continue;
    centre_x += d->geom_xpos[3 * g];
    geoms += 1;
  }
  const double goal = centre_x / std::max(geoms, 1.0) + offset_[0];
  // COM x minus the goal with the legs leaned by theta and the soles where they were.
  auto lean = [&](double theta) {
    mju_copy(d->qpos, m->qpos0, m->nq);
    for (int k : hips) d->qpos[body_.joints[static_cast<size_t>(k)].qpos] -= theta;
    for (int k : feet) d->qpos[body_.joints[static_cast<size_t>(k)].qpos] += theta;
    mj_kinematics(m, d);
    for (int i = 0; i < 3; i += 2) {
      double shift = 0;
      for (int s = 0; s < 2; ++s)
        shift += d->xpos[3 * body_.feet[static_cast<size_t>(s)] + i] -
                 foot0[static_cast<size_t>(s)][static_cast<size_t>(i)];
      // World x and z: a free root's position, or a planar root's slides.
      const int slot = body_.root == RootKind::kPlanar ? (i == 0 ? body_.root_x_qpos : body_.root_z_qpos)
                                                       : body_.root_qpos + i;
      d->qpos[slot] -= shift / 2;
    }
    mj_kinematics(m, d);
    mj_comPos(m, d);
    return d->subtree_com[3 * root] - goal;
  };
  // Secant iterations; the COM moves about its height times theta.
  double t0 = 0, e0 = lean(t0), t1 = 0.05, e1 = lean(t1);
  for (int it = 0; it < 20 && std::fabs(e1) > 1e-6 && std::fabs(e1 - e0) > 1e-12; ++it) {
    const double t2 = t1 - e1 * (t1 - t0) / (e1 - e0);
    t0 = t1;
    e0 = e1;
    t1 = std::clamp(t2, -0.5, 0.5);
    e1 = lean(t1);
  }
  std::vector<double> qpos(d->qpos, d->qpos + m->nq);
  mj_deleteData(d);
  return qpos;
}

void StanceController::measure(const mjModel* m, const mjData* d) {
  const int root = body_.root_body;
  const double* c = d->subtree_com + 3 * root;
  com_ = {c[0], c[1], c[2]};
  // COM velocity from the bodies' com-based velocities (d->cvel: angular, then linear at
  // the subtree COM of the tree's root, world orientation).
  double p[3] = {0, 0, 0};
  for (int b : body_.links) {
    const double* v = d->cvel + 6 * b;
    const double* o = d->subtree_com + 3 * m->body_rootid[b];
    double r[3] = {d->xipos[3 * b] - o[0], d->xipos[3 * b + 1] - o[1], d->xipos[3 * b + 2] - o[2]};
    double w_r[3];
    mju_cross(w_r, v, r);
    for (int i = 0; i < 3; ++i) p[i] += m->body_mass[b] * (v[3 + i] + w_r[i]);
  }
  for (int i = 0; i < 3; ++i) com_vel_[static_cast<size_t>(i)] = p[i] / mass_;
}

bool StanceController::foot_contact(const mjData* d, int side) const {
  for (int c = 0; c < d->ncon; ++c) {
    const mjContact& con = d->contact[c];
    if (geom_side_[static_cast<size_t>(con.geom1)] == side ||
        geom_side_[static_cast<size_t>(con.geom2)] == side) {
      return true;
    }
  }
  return false;
}

void StanceController::set_pitches(double root, double torso, const std::array<double, 2>& feet) {
  pitch_root_ = root;
  pitch_torso_ = torso;
  pitch_foot_ = feet;
  update_targets();
}

void StanceController::set_joint_gains(int k, double kp, double kd) {
  kp_.at(static_cast<size_t>(k)) = kp;
  kd_gain_.at(static_cast<size_t>(k)) = kd;
}

void StanceController::set_root_gains(double kp, double kd) {
  root_kp_ = kp;
  root_kd_ = kd;
}

void StanceController::reset(const mjModel* m, const mjData* d) {
  measure(m, d);
  height_target_ = com_[2];
  const int root = body_.root_body;
  // A planar character faces along its plane whatever its pitch (a root pitched past 90
  // degrees would turn the yaw of its x axis round).
  heading_ = body_.root == RootKind::kPlanar ? yaw_of(root_standing_.data()) : yaw_of(d->xquat + 4 * root);
  const double turn = heading_ - yaw_of(root_standing_.data());
  heading_quat_ = {std::cos(turn / 2), 0, 0, std::sin(turn / 2)};
  update_targets();
}

StanceController::Pitches StanceController::measured_pitches(const mjData* d) const {
  const double h[2] = {std::cos(heading_), std::sin(heading_)};
  // Pitch (positive backwards) of a forward axis: its elevation along the heading.
  auto elevation = [&](const double* x) { return std::atan2(x[2], x[0] * h[0] + x[1] * h[1]); };
  auto forward = [](const double* quat, double* x) {
    double R[9];
    mju_quat2Mat(R, quat);
    x[0] = R[0];
    x[1] = R[3];
    x[2] = R[6];
  };
  Pitches p;
  double standing[4], x[3];
  mju_mulQuat(standing, heading_quat_.data(), root_standing_.data());
  const int root = body_.root_body;
  forward(standing, x);
  const double root0 = elevation(x);
  {  // d->xmat's first column is at 0, 3, 6
    const double* R = d->xmat + 9 * root;
    const double col[3] = {R[0], R[3], R[6]};
    p.root = elevation(col) - root0;
  }
  p.torso = p.root;
  if (torso_body_ >= 0) {
    double torso[4];
    mju_mulQuat(torso, standing, torso_in_root_.data());
    forward(torso, x);
    const double* R = d->xmat + 9 * torso_body_;
    const double col[3] = {R[0], R[3], R[6]};
    p.torso = elevation(col) - elevation(x);
  }
  double foot = 0;
  for (int s = 0; s < 2; ++s) {
    double up[3];
    mju_mulMatVec(up, d->xmat + 9 * body_.feet[static_cast<size_t>(s)], foot_up_[static_cast<size_t>(s)].data(), 3, 3);
    foot += 0.5 * std::atan2(-(up[0] * h[0] + up[1] * h[1]), up[2]);
  }
  p.foot = foot;
  return p;
}

void StanceController::update_targets() {
  // A turn by `pitch` about minus the heading's lateral axis (-sin h, cos h, 0).
  auto pitched = [&](double pitch, const double* q, double* out) {
    const double s = std::sin(pitch / 2);
    const double p[4] = {std::cos(pitch / 2), s * std::sin(heading_), -s * std::cos(heading_), 0};
    mju_mulQuat(out, p, q);
  };
  double standing[4], torso[4];
  mju_mulQuat(standing, heading_quat_.data(), root_standing_.data());
  pitched(pitch_root_, standing, root_target_.data());
  mju_mulQuat(torso, standing, torso_in_root_.data());
  pitched(pitch_torso_, torso, torso_target_.data());
  const double identity[4] = {1, 0, 0, 0};
  const double z[3] = {0, 0, 1};
  for (size_t s = 0; s < 2; ++s) {
    double foot[4];
    pitched(pitch_foot_[s], identity, foot);
    mju_rotVecQuat(foot_up_target_[s].data(), z, foot);
  }
}

void StanceController::control(const mjModel* m, const mjData* d, JointDrive& drive) {
  const int n = body_.dof();
  const int root = body_.root_body;
  measure(m, d);
  for (int s = 0; s < 2; ++s) stance_[static_cast<size_t>(s)] = foot_contact(d, s);
  const int legs = (stance_[0] ? 1 : 0) + (stance_[1] ? 1 : 0);
  rows_ = drive.damping() == Damping::kConstrained;
  if (rows_) {
    row_.resize(static_cast<size_t>(n));
    row_used_.assign(static_cast<size_t>(n), 0);
    jacobian_bodies_.clear();
  }

  // Support polygon, its centre, the soles' height.
  force_ = {0, 0, 0};
  load_ = {0, 0};
  leg_force_ = {};
  std::array<Vec2, 2> foot_centre{};  // centre of each stance sole (m, world x y)
  if (legs > 0) {
    std::vector<Vec2> corners;
    Vec2 centre{0, 0};
    std::array<double, 2> geoms{0, 0};
    double centres = 0, sole = INFINITY;
    for (int g = 0; g < m->ngeom; ++g) {
      const int s = geom_side_[static_cast<size_t>(g)];
      if (s < 0 || !stance_[static_cast<size_t>(s)]) continue;
      const double* x = d->geom_xpos + 3 * g;
      const double* R = d->geom_xmat + 9 * g;
      const double* size = m->geom_size + 3 * g;
      if (m->geom_type[g] == mjGEOM_BOX) {
        for (int corner = 0; corner < 8; ++corner) {
          const double l[3] = {(corner & 1 ? 1 : -1) * size[0], (corner & 2 ? 1 : -1) * size[1],
                               (corner & 4 ? 1 : -1) * size[2]};
          double w[3];
          mju_mulMatVec(w, R, l, 3, 3);
          corners.push_back({x[0] + w[0], x[1] + w[1]});
          sole = std::min(sole, x[2] + w[2]);
        }
      } else {
        const double r = m->geom_rbound[g];
        for (int corner = 0; corner < 4; ++corner) {
          corners.push_back({x[0] + (corner & 1 ? r : -r), x[1] + (corner & 2 ? r : -r)});
        }
        sole = std::min(sole, x[2] - r);
      }
      centre[0] += x[0];
      centre[1] += x[1];
      centres += 1;
      foot_centre[static_cast<size_t>(s)][0] += x[0];
      foot_centre[static_cast<size_t>(s)][1] += x[1];
      geoms[static_cast<size_t>(s)] += 1;
    }
    support_ = {centre[0] / centres, centre[1] / centres};
    for (int s = 0; s < 2; ++s) {
      for (double& v : foot_centre[static_cast<size_t>(s)])
        v /= std::max(geoms[static_cast<size_t>(s)], 1.0);
    }

    const double M = mass_;
    double fx =
        M * (gains_.com_kp * (support_[0] + offset_[0] - com_[0]) - gains_.com_kd * (com_vel_[0] - velocity_[0]));
    double fy =
        M * (gains_.com_kp * (support_[1] + offset_[1] - com_[1]) - gains_.com_kd * (com_vel_[1] - velocity_[1]));
    const double servo = com_force_ == ComForce::kBalance ? gains_.height_kp * (height_target_ - com_[2]) : 0;
    double fz = M * (gravity_ + servo - gains_.height_kd * com_vel_[2]);
    fz = std::max(fz, 0.1 * M * gravity_);
    // Keep the centre of pressure inside the support polygon.
    const double h = std::max(com_[2] - sole, 0.05);
    const std::vector<Vec2> polygon = shrink(convex_hull(corners), gains_.cop_margin);
    const Vec2 cop{com_[0] - h * fx / fz, com_[1] - h * fy / fz};
    const Vec2 held = project(polygon, cop);
    if (held != cop && com_force_ != ComForce::kPush) {
      fx = (com_[0] - held[0]) * fz / h;
      fy = (com_[1] - held[1]) * fz / h;
    }
    if (com_force_ == ComForce::kNone) fx = fy = fz = 0;
    force_ = {fx, fy, fz};

    // Share the load: the centre of pressure `held` between the soles' centres gives each
    // stance foot its part alpha_s (by where `held` lies on the line between them); each
    // foot's own centre of pressure is its sole's centre moved by what lies off that line,
    // so that sum alpha_s cop_s = held; and each leg pushes alpha_s F from there. The legs'
    // forces add up to F, their moment about the COM is (held - c) x F = 0, and they do not
    // squeeze the feet apart.
    // A push is shared otherwise: its F_z is held at a tenth of the weight while the COM
    // rises (F_z = M (g - height_kd v_z)), so the centre of pressure it implies lies
    // h F_xy / F_z from the COM, ten times further than in balance, and the load split by
    // it turned a lateral COM speed of 1 cm/s into 60 % of the push on one leg (left and
    // right then parted threefold per step), while each foot's point moved sideways by it
    // rolled the bird's feet on their front edges (its two sides parted twofold every
    // 14 ms). Two stance legs push half each, from their own soles' centres moved only
    // along the heading.
    const bool push = com_force_ == ComForce::kPush;
    std::array<double, 2> load{stance_[0] ? 1.0 : 0.0, stance_[1] ? 1.0 : 0.0};
    const int first = stance_[0] ? 0 : 1;
    Vec2 residual{held[0] - foot_centre[static_cast<size_t>(first)][0],
                  held[1] - foot_centre[static_cast<size_t>(first)][1]};
    if (legs == 2) {
      const Vec2& l = foot_centre[0];
      const Vec2& r = foot_centre[1];
      const double dx = l[0] - r[0], dy = l[1] - r[1];
      const double len2 = dx * dx + dy * dy;
      double alpha = push || len2 <= 1e-8 ? 0.5 : ((held[0] - r[0]) * dx + (held[1] - r[1]) * dy) / len2;
      alpha = std::clamp(alpha, 0.0, 1.0);
      load = {alpha, 1 - alpha};
      residual = {held[0] - (alpha * l[0] + (1 - alpha) * r[0]),
                  held[1] - (alpha * l[1] + (1 - alpha) * r[1])};
      if (push) {  // only the part along the heading
        const double c = std::cos(heading_), sn = std::sin(heading_);
        const double along = residual[0] * c + residual[1] * sn;
        residual = {along * c, along * sn};
      }
    }
    for (int s = 0; s < 2; ++s) {
      const Vec2& f = foot_centre[static_cast<size_t>(s)];
      const double a = load[static_cast<size_t>(s)];
      leg_force_[static_cast<size_t>(s)] = {a * fx, a * fy, a * fz};
      leg_cop_[static_cast<size_t>(s)] = {f[0] + residual[0], f[1] + residual[1], sole};
    }
    load_ = load;

    // Yaw: equal and opposite pushes of the two legs at right angles to the line between
    // their centres of pressure, a moment about the vertical and no net force.
    yaw_force_ = 0;
    if (legs == 2 && (gains_.yaw_kp > 0 || gains_.yaw_kd > 0)) {
      const auto& cl = leg_cop_[0];
      const auto& cr = leg_cop_[1];
      const double dx = cl[0] - cr[0], dy = cl[1] - cr[1];
      const double width = std::hypot(dx, dy);
      if (width > 0.05) {
        double e[3];
        rotation_error(root_target_.data(), d->xquat + 4 * root, e);
        const double wz = d->cvel[6 * root + 2];
        const double moment = gains_.yaw_kp * e[2] - gains_.yaw_kd * wz;
        const double limit = 0.25 * fz;
        const double yaw = std::clamp(moment / width, -limit, limit);
        const double nx = -dy / width, ny = dx / width;
        for (int s = 0; s < 2; ++s) {
          const double sign = s == 0 ? 1.0 : -1.0;
          leg_force_[static_cast<size_t>(s)][0] += sign * yaw * nx;
          leg_force_[static_cast<size_t>(s)][1] += sign * yaw * ny;
        }
        yaw_force_ = yaw;
      }
    }
  }

  // Default: PD toward the targets, gravity compensation off the stance legs.
  for (int k = 0; k < n; ++k) {
    const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
    double u = kp_[static_cast<size_t>(k)] * (targets_[static_cast<size_t>(k)] - d->qpos[j.qpos]);
    const int leg = leg_of_[static_cast<size_t>(k)];
    const bool in_stance = leg >= 0 && stance_[static_cast<size_t>(leg)];
    if (gains_.gravity_compensation && !in_stance) u += gravity_torque(m, d, j, gravity_);
    u_[static_cast<size_t>(k)] = u;
    kd_[static_cast<size_t>(k)] = kd_gain_[static_cast<size_t>(k)];
  }

  // Feet flat: the rotation that takes the foot's standing up vector to world up.
  for (int s = 0; s < 2; ++s) {
    const int foot = body_.feet[static_cast<size_t>(s)];
    const double* R = d->xmat + 9 * foot;
    const double* up0 = foot_up_[static_cast<size_t>(s)].data();
    double up[3];
    mju_mulMatVec(up, R, up0, 3, 3);
    const double* z = foot_up_target_[static_cast<size_t>(s)].data();
    double e[3];
    mju_cross(e, up, z);
    const double sin_angle = mju_norm3(e);
    const double angle = std::atan2(sin_angle, dot3(up, z));
    if (sin_angle > 1e-12) mju_scl3(e, e, angle / sin_angle);
    const double* w_parent = d->cvel + 6 * m->body_parentid[foot];
    for (int k : legs_[static_cast<size_t>(s)].foot) {
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      const double* a = d->xaxis + 3 * j.joint;
      const double kp = kp_[static_cast<size_t>(k)], kd = kd_gain_[static_cast<size_t>(k)];
      // The damper on the foot's world angular velocity about the axis, a . w_parent + qdot.
      u_[static_cast<size_t>(k)] = kp * dot3(a, e);
      if (rows_) {
        add_body_damping(m, d, k, m->body_parentid[foot], 1.0);
      } else {
        u_[static_cast<size_t>(k)] -= kd * dot3(a, w_parent);
      }
      kd_[static_cast<size_t>(k)] = kd;
    }
  }

  // Torso: its standing orientation relative to the root's target, in world.
  if (torso_body_ >= 0) {
    double e[3];
    rotation_error(torso_target_.data(), d->xquat + 4 * torso_body_, e);
    const double* w_parent = d->cvel + 6 * m->body_parentid[torso_body_];
    for (int k : waist_) {
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      const double* a = d->xaxis + 3 * j.joint;
      const double kp = kp_[static_cast<size_t>(k)], kd = kd_gain_[static_cast<size_t>(k)];
      double u = kp * dot3(a, e);
      if (rows_) {
        add_body_damping(m, d, k, m->body_parentid[torso_body_], 1.0);
      } else {
        u -= kd * dot3(a, w_parent);
      }
      if (gains_.gravity_compensation) u += gravity_torque(m, d, j, gravity_);
      u_[static_cast<size_t>(k)] = u;
      kd_[static_cast<size_t>(k)] = kd;
    }
  }

  // Stance legs: each realizes its share of the virtual force and of the torque the root
  // needs, tau = J^T (F_leg, T_leg), J the Jacobian of the point where the leg's force acts
  // and of the root's orientation with the foot as the base: for every hinge j of the leg,
  // tau_j = -a_j . ((cop_leg - p_j) x F_leg) - a_j . T_leg. The root needs its PD
  // torque, T = root_kp e - root_kd w_root, plus what the other hinges on it (waist, swing
  // hips) take away, sum of tau_o a_o. Driving the whole leg this way (not just the hip, as
  // SIMBICON's tau_stance = -tau_torso - tau_swing does) leaves the legs' sideways sway,
  // which does not turn the root, to the COM force alone.
  if (legs > 0) {
    double e[3];
    rotation_error(root_target_.data(), d->xquat + 4 * root, e);
    double torque[3];  // T without its damping part
    for (int i = 0; i < 3; ++i) torque[i] = root_kp_ * e[i];
    for (int k : root_children_) {
      const int leg = leg_of_[static_cast<size_t>(k)];
      if (leg >= 0 && stance_[static_cast<size_t>(leg)]) continue;
      const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
      const double tau =
          std::clamp(u_[static_cast<size_t>(k)] - kd_[static_cast<size_t>(k)] * damped_velocity_now(d, k),
                     -j.torque_limit, j.torque_limit);
      const double* a = d->xaxis + 3 * j.joint;
      for (int i = 0; i < 3; ++i) torque[i] += tau * a[i];
    }
    const double* w_root = d->cvel + 6 * root;
    // The legs share T by load, each stance leg at least a tenth.
    std::array<double, 2> share{};
    for (int s = 0; s < 2; ++s)
      share[static_cast<size_t>(s)] =
          stance_[static_cast<size_t>(s)] ? std::max(load_[static_cast<size_t>(s)], 0.1) : 0.0;
    const double total = share[0] + share[1];
    for (int s = 0; s < 2; ++s) {
      if (!stance_[static_cast<size_t>(s)]) continue;
      const double w = share[static_cast<size_t>(s)] / total;
      const double* f = leg_force_[static_cast<size_t>(s)].data();
      for (int k : legs_[static_cast<size_t>(s)].joints) {
        const CharacterJoint& j = body_.joints[static_cast<size_t>(k)];
        const double* a = d->xaxis + 3 * j.joint;
        const double* p = d->xanchor + 3 * j.joint;
        const double* cop = leg_cop_[static_cast<size_t>(s)].data();
        const double r[3] = {cop[0] - p[0], cop[1] - p[1], cop[2] - p[2]};
        const double jt = -axis_moment(a, r, f) - w * dot3(a, torque);
        if (is_hip_[static_cast<size_t>(k)]) {
          // The hip replaces its joint PD. Root damping +w root_kd (a . w_root), by the
          // identity a . w_root = a . w_thigh - qdot (the hinges of a universal joint are
          // orthogonal): its -qdot part is the hip's own damping, implicit in the drive.
          const double* w_child = d->cvel + 6 * j.body;
          u_[static_cast<size_t>(k)] = jt;
          kd_[static_cast<size_t>(k)] = w * root_kd_;
          if (rows_) {
            row_used_[static_cast<size_t>(k)] = 0;  // replaces the joint PD's damper
            add_body_damping(m, d, k, j.body, -1.0);
          } else {
            u_[static_cast<size_t>(k)] += w * root_kd_ * dot3(a, w_child);
          }
        } else {
          const double kd = kd_[static_cast<size_t>(k)];
          if (rows_ && kd > 0) {
            u_[static_cast<size_t>(k)] += jt;
            add_body_damping(m, d, k, root, -w * root_kd_ / kd);
          } else {
            u_[static_cast<size_t>(k)] += jt + w * root_kd_ * dot3(a, w_root);
          }
        }
      }
    }
  }

  for (int k = 0; k < n; ++k) {
    const size_t kk = static_cast<size_t>(k);
    if (!rows_ || !row_used_[kk]) {
      drive.set(k, u_[kk], kd_[kk]);
      continue;
    }
    damped_.clear();
    const std::vector<double>& row = row_[kk];
    for (int i = 0; i < m->nv; ++i) {
      const double weight = row[static_cast<size_t>(i)] + (i == body_.joints[kk].dof ? 1.0 : 0.0);
      if (weight != 0) damped_.push_back({i, weight});
    }
    drive.set(k, u_[kk], kd_[kk], damped_);
  }
}

void StanceController::add_body_damping(const mjModel* m, const mjData* d, int k, int body, double weight) {
  const size_t kk = static_cast<size_t>(k), nv = static_cast<size_t>(m->nv);
  std::vector<double>& row = row_[kk];
  if (!row_used_[kk]) row.assign(nv, 0.0);
  row_used_[kk] = 1;
  // w_body = J qvel (world frame), J from mj_jacBody once a step per body.
  size_t slot = 0;
  while (slot < jacobian_bodies_.size() && jacobian_bodies_[slot] != body) ++slot;
  if (slot == jacobian_bodies_.size()) {
    jacobian_bodies_.push_back(body);
    if (jacobians_.size() <= slot) jacobians_.resize(slot + 1);
    jacobians_[slot].resize(3 * nv);
    mj_jacBody(m, d, nullptr, jacobians_[slot].data(), body);
  }
  const std::vector<mjtNum>& jacr = jacobians_[slot];
  const double* a = d->xaxis + 3 * body_.joints[kk].joint;
  for (size_t i = 0; i < nv; ++i)
    row[i] += weight * (a[0] * jacr[i] + a[1] * jacr[nv + i] + a[2] * jacr[2 * nv + i]);
}

double StanceController::damped_velocity_now(const mjData* d, int k) const {
  const size_t kk = static_cast<size_t>(k);
  const int dof = body_.joints[kk].dof;
  if (!rows_ || !row_used_[kk]) return d->qvel[dof];
  double v = d->qvel[dof];
  const std::vector<double>& row = row_[kk];
  for (size_t i = 0; i < row.size(); ++i) v += row[i] * d->qvel[i];
  return v;
}

}  // namespace diverse
