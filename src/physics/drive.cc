#include "physics/drive.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace diverse {

std::vector<DrivenJoint> driven_joints(const mjModel* m) {
  // A joint's net torque is the drive's only if a single actuator acts on it.
  std::vector<int> actuators_on(static_cast<size_t>(m->njnt), 0);
  for (int a = 0; a < m->nu; ++a) {
    if (m->actuator_trntype[a] == mjTRN_JOINT || m->actuator_trntype[a] == mjTRN_JOINTINPARENT)
      ++actuators_on[static_cast<size_t>(m->actuator_trnid[2 * a])];
  }
  std::vector<DrivenJoint> joints;
  for (int a = 0; a < m->nu; ++a) {
    if (m->actuator_trntype[a] != mjTRN_JOINT) continue;
    const int j = m->actuator_trnid[2 * a];
    if (j < 0 || actuators_on[static_cast<size_t>(j)] != 1) continue;
    if (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) continue;
    // A motor: force = ctrl exactly (gain 1, no bias, no activation dynamics), so the
    // motor torque on the joint is the actuator force times gear 1.
    const mjtNum* gain = m->actuator_gainprm + static_cast<long>(a) * mjNGAIN;
    if (m->actuator_dyntype[a] != mjDYN_NONE || m->actuator_gaintype[a] != mjGAIN_FIXED ||
        gain[0] != 1 || m->actuator_biastype[a] != mjBIAS_NONE)
      continue;
    if (m->actuator_gear[6 * a] != 1) continue;
    const mjtNum* range = m->actuator_forcerange + 2 * a;
    if (!m->actuator_forcelimited[a] || !(range[1] > 0) || range[0] != -range[1]) continue;
    joints.push_back({a, m->jnt_dofadr[j], range[1]});
  }
  return joints;
}

JointDrive::JointDrive(std::vector<DrivenJoint> joints, SaturatedDrive saturated, Damping damping)
    : joints_(std::move(joints)),
      saturated_(saturated),
      damping_(damping),
      u_(joints_.size(), 0.0),
      kd_(joints_.size(), 0.0),
      damped_(joints_.size()),
      torque_(joints_.size(), 0.0),
      qdot_(joints_.size(), 0.0),
      explicit_(joints_.size(), 0) {
  for (const DrivenJoint& j : joints_) dofs_.push_back(j.dof);
}

bool JointDrive::apply(mjModel* m, mjData* d) {
  ++counts_.steps;
  redone_ = false;
  bool damping_changed = false;
  const bool constrained = damping_ == Damping::kConstrained;
  if (constrained) solve_constrained(m, d);
  for (size_t k = 0; k < joints_.size(); ++k) {
    const DrivenJoint& j = joints_[k];
    const double u = u_[k], kd = kd_[k], qdot = d->qvel[j.dof];
    qdot_[k] = qdot;
    const double request = u - kd * qdot;
    // Implicit only while neither the motor (ctrl = u) nor the request is saturated: a
    // saturated request is exactly what the explicit way delivers, and implicit damping
    // on top of a clamped motor is what broke the limit before.
    const bool implicit = !constrained && std::fabs(u) <= j.limit && std::fabs(request) <= j.limit;
    explicit_[k] = implicit ? 0 : 1;
    d->ctrl[j.actuator] = implicit ? u : constrained ? torque_[k] : explicit_torque(m, d, k, qdot);
    const double damping = implicit ? kd : 0.0;
    if (m->dof_damping[j.dof] != damping) {
      m->dof_damping[j.dof] = damping;
      damping_changed = true;
    }
  }
  return damping_changed;
}

double JointDrive::explicit_torque(const mjModel* m, mjData* d, size_t k, double qdot) {
  const DrivenJoint& j = joints_[k];
  double request = u_[k] - kd_[k] * qdot;
  if (saturated_ == SaturatedDrive::kStablePd && kd_[k] > 0) {
    // (M^-1)_kk from the factorization mj_step1 left in d->qLD (header).
    const auto nv = static_cast<size_t>(m->nv);
    if (unit_.size() != nv) {
      unit_.assign(nv, 0);
      response_.assign(nv, 0);
    }
    unit_[static_cast<size_t>(j.dof)] = 1;
    mj_solveM(m, d, response_.data(), unit_.data(), 1);
    unit_[static_cast<size_t>(j.dof)] = 0;
    const double inverse_inertia = response_[static_cast<size_t>(j.dof)];
    if (inverse_inertia > 0 && std::isfinite(inverse_inertia))
      request /= 1 + m->opt.timestep * kd_[k] * inverse_inertia;
  }
  return std::clamp(request, -j.limit, j.limit);
}

void JointDrive::solve_constrained(const mjModel* m, mjData* d) {
  const int n = size(), nv = m->nv, nefc = d->nefc;
  // The inertia with the step's constraint rows held, soft as MuJoCo makes them (R):
  // H = M + J^T R^-1 J, whose inverse is M^-1 - M^-1 J^T (J M^-1 J^T + R)^-1 J M^-1
  // (Woodbury), the response to a torque while the constraints hold. J^T R^-1 J is summed
  // over each row's non-zeros (a contact row moves a few of a character's dofs).
  inertia_.resize(nv, nv);
  mj_fullM(m, inertia_.data(), d->qM);  // symmetric: row- or column-major alike
  if (nefc > 0) {
    row_.resize(static_cast<size_t>(nv));
    basis_.assign(static_cast<size_t>(nefc), 0.0);
    for (int i = 0; i < nefc; ++i) {
      const mjtNum* jrow = d->efc_J + static_cast<std::ptrdiff_t>(i) * nv;
      if (mj_isSparse(m)) {
        basis_[static_cast<size_t>(i)] = 1;
        mj_mulJacTVec(m, d, row_.data(), basis_.data());
        basis_[static_cast<size_t>(i)] = 0;
        jrow = row_.data();
      }
      nonzero_.clear();
      for (int a = 0; a < nv; ++a)
        if (jrow[a] != 0) nonzero_.push_back(a);
      const double w = 1 / d->efc_R[i];
      for (int a : nonzero_)
        for (int b : nonzero_)
          inertia_(a, b) += w * jrow[a] * jrow[b];
    }
  }
  // Each joint's damped velocity now (c_k qdot) and its request without the step's part,
  // r_k = u_k - kd_k c_k qdot. A negative or non-finite gain is no damper: the torques are
  // then NaN, which the rollout reports as an instability (MuJoCo's bad-ctrl warning), as
  // the way with MuJoCo's damping does through dof_damping.
  const double h = m->opt.timestep;
  rhs_.resize(n);
  bool symmetric = true;
  for (int k = 0; k < n; ++k) {
    const size_t kk = static_cast<size_t>(k);
    if (!damped_[kk].empty()) symmetric = false;
    const double velocity = damped_velocity(kk, d->qvel);
    const double kd = kd_[kk];
    rhs_[k] = kd >= 0 && std::isfinite(kd) ? u_[kk] - kd * velocity
                                           : std::numeric_limits<double>::quiet_NaN();
  }
  // tau = u - Kd (c qdot + h C x) with H x = S^T tau (x: the step's velocity change per
  // unit of step). With every joint free, substituting tau gives one nv x nv solve,
  //
  //     A x = S^T r,   A = H + h S^T Kd C,   tau = r - h Kd C x,
  //
  // A symmetric positive definite when every damper is on its joint's own velocity. A
  // joint whose torque would pass its limit is held there (the one furthest beyond first)
  // and the rest solved again: holding joint w takes h kd_w s_w c_w^T out of A and puts
  // s_w (tau_w - r_w) into the right-hand side, a rank-one change each, so with the set W
  // held (Woodbury, P_w = A^-1 s_w, Z = A^-1 U, U = [h kd_w s_w], V = [c_w]):
  //
  //     y = x_0 + sum_w P_w (tau_w - r_w),   x_W = y + Z (I - V^T Z)^-1 V^T y,
  //
  // O(nv^2) a held joint after A's one factorization.
  system_ = inertia_;
  step_rhs_.setZero(nv);
  for (int k = 0; k < n; ++k) {
    const size_t kk = static_cast<size_t>(k);
    const int dof = joints_[kk].dof;
    step_rhs_[dof] += rhs_[k];
    const double gain = h * kd_[kk];
    const std::vector<DampedDof>& c = damped_[kk];
    if (c.empty()) {
      system_(dof, dof) += gain;
    } else {
      for (const DampedDof& t : c) system_(dof, t.dof) += gain * t.weight;
    }
  }
  if (symmetric) {
    system_llt_.compute(system_);
    free_change_ = system_llt_.solve(step_rhs_);
  } else {
    system_lu_.compute(system_);
    free_change_ = system_lu_.solve(step_rhs_);
  }
  change_ = free_change_;
  held_.clear();
  held_response_.resize(nv, n);  // columns 0..p-1 in use: P_w of the held joints, in order
  capacitance_.resize(n, n);     // its top-left p x p block in use
  for (int round = 0; round <= n; ++round) {
    int worst = -1;
    double worst_ratio = 1;
    for (int k = 0; k < n; ++k) {
      const size_t kk = static_cast<size_t>(k);
      if (std::find(held_.begin(), held_.end(), k) != held_.end()) continue;
      // A non-finite request or state gives a non-finite torque, which the rollout
      // reports as an instability rather than a quiet zero.
      torque_[kk] = rhs_[k] - h * kd_[kk] * damped_velocity(kk, change_);
      const double ratio = std::fabs(torque_[kk]) / joints_[kk].limit;
      if (ratio > worst_ratio) {
        worst_ratio = ratio;
        worst = k;
      }
    }
    if (worst < 0) break;
    const size_t kw = static_cast<size_t>(worst);
    torque_[kw] = std::clamp(torque_[kw], -joints_[kw].limit, joints_[kw].limit);
    held_.push_back(worst);
    // P_w = A^-1 s_w, then x_W from the held set.
    const auto p = static_cast<Eigen::Index>(held_.size());
    unit_rhs_.setZero(nv);
    unit_rhs_[joints_[kw].dof] = 1;
    if (symmetric) {
      held_response_.col(p - 1) = system_llt_.solve(unit_rhs_);
    } else {
      held_response_.col(p - 1) = system_lu_.solve(unit_rhs_);
    }
    change_ = free_change_;
    for (Eigen::Index i = 0; i < p; ++i) {
      const size_t ki = static_cast<size_t>(held_[static_cast<size_t>(i)]);
      change_ += held_response_.col(i) * (torque_[ki] - rhs_[static_cast<Eigen::Index>(ki)]);
    }
    // capacitance = I - V^T Z, Z_j = h kd_j P_j (only the new joint's row and column are
    // new); then x_W = y + Z capacitance^-1 V^T y.
    for (Eigen::Index i = 0; i < p; ++i) {
      const size_t ki = static_cast<size_t>(held_[static_cast<size_t>(i)]);
      for (Eigen::Index j = 0; j < p; ++j) {
        if (i != p - 1 && j != p - 1) continue;
        const size_t kj = static_cast<size_t>(held_[static_cast<size_t>(j)]);
        capacitance_(i, j) = (i == j ? 1.0 : 0.0) -
                             h * kd_[kj] * damped_velocity(ki, held_response_.col(j));
      }
    }
    projected_.resize(p);
    for (Eigen::Index i = 0; i < p; ++i)
      projected_[i] = damped_velocity(static_cast<size_t>(held_[static_cast<size_t>(i)]), change_);
    capacitance_lu_.compute(capacitance_.topLeftCorner(p, p));
    weights_ = capacitance_lu_.solve(projected_);
    for (Eigen::Index j = 0; j < p; ++j) {
      const size_t kj = static_cast<size_t>(held_[static_cast<size_t>(j)]);
      change_ += (h * kd_[kj] * weights_[j]) * held_response_.col(j);
    }
  }
}

template <typename Vector>
double JointDrive::damped_velocity(size_t k, const Vector& v) const {
  const std::vector<DampedDof>& c = damped_[k];
  if (c.empty()) return v[joints_[k].dof];
  double sum = 0;
  for (const DampedDof& t : c) sum += t.weight * v[t.dof];
  return sum;
}

void JointDrive::make_explicit(mjModel* m, mjData* d, size_t k) {
  const DrivenJoint& j = joints_[k];
  explicit_[k] = 1;
  d->ctrl[j.actuator] = damping_ == Damping::kConstrained ? torque_[k] : explicit_torque(m, d, k, qdot_[k]);
  m->dof_damping[j.dof] = 0;
}

bool JointDrive::check(mjModel* m, mjData* d, bool all_explicit) {
  bool holds = true;
  for (size_t k = 0; k < joints_.size(); ++k) {
    if (explicit_[k]) continue;
    const DrivenJoint& j = joints_[k];
    // The same expression check_net_torque() evaluates on the replay, so a step accepted
    // here is within its limit there, bit for bit.
    const double net = d->actuator_force[j.actuator] - m->dof_damping[j.dof] * d->qvel[j.dof];
    if (std::fabs(net) > j.limit) {
      holds = false;
      if (!all_explicit) make_explicit(m, d, k);
    }
  }
  if (holds) return true;
  if (all_explicit) {
    for (size_t k = 0; k < joints_.size(); ++k) {
      if (!explicit_[k]) make_explicit(m, d, k);
    }
    ++counts_.all_explicit_steps;
  }
  if (!redone_) ++counts_.redone_steps;
  redone_ = true;
  ++counts_.redos;
  return false;
}

}  // namespace diverse
