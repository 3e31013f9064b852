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
  inertia_llt_.compute(inertia_);
  // response = H^-1 S^T: every dof's acceleration per unit torque at each driven joint.
  response_cols_.setZero(nv, n);
  for (int k = 0; k < n; ++k) response_cols_(joints_[static_cast<size_t>(k)].dof, k) = 1;
  inertia_llt_.solveInPlace(response_cols_);
  // The dampers' velocities now and their response: B = C H^-1 S^T.
  damped_response_.resize(n, n);
  damped_velocity_.resize(n);
  for (int k = 0; k < n; ++k) {
    const std::vector<DampedDof>& c = damped_[static_cast<size_t>(k)];
    if (c.empty()) {
      const int dof = joints_[static_cast<size_t>(k)].dof;
      damped_response_.row(k) = response_cols_.row(dof);
      damped_velocity_[k] = d->qvel[dof];
    } else {
      damped_response_.row(k).setZero();
      damped_velocity_[k] = 0;
      for (const DampedDof& t : c) {
        damped_response_.row(k) += t.weight * response_cols_.row(t.dof);
        damped_velocity_[k] += t.weight * d->qvel[t.dof];
      }
    }
  }
  // tau = u - Kd (c qdot + h B tau): (I + h Kd B) tau = u - Kd c qdot. A joint whose
  // torque would pass its limit is held there, the one furthest beyond first, and the
  // rest solved again; the inverse of the free joints' system is updated as each is held
  // (Schur complement), so each round costs O(n^2).
  const double h = m->opt.timestep;
  system_.setIdentity(n, n);
  for (int a = 0; a < n; ++a) system_.row(a) += h * kd_[static_cast<size_t>(a)] * damped_response_.row(a);
  system_lu_.compute(system_);
  inverse_ = system_lu_.inverse();
  free_.resize(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) free_[static_cast<size_t>(k)] = k;
  rhs_.resize(n);
  for (int k = 0; k < n; ++k)
    rhs_[k] = u_[static_cast<size_t>(k)] - kd_[static_cast<size_t>(k)] * damped_velocity_[k];
  // A negative or non-finite gain is no damper: that joint's torque is NaN, which the
  // rollout reports as an instability (MuJoCo's bad-ctrl warning), as the way with
  // MuJoCo's damping does through dof_damping.
  for (int k = 0; k < n; ++k) {
    const double kd = kd_[static_cast<size_t>(k)];
    if (!(kd >= 0) || !std::isfinite(kd)) rhs_[k] = std::numeric_limits<double>::quiet_NaN();
  }
  for (int round = 0; round < n; ++round) {
    int worst = -1;
    double worst_ratio = 1;
    for (int a : free_) {
      double t = 0;
      for (int b : free_) t += inverse_(a, b) * rhs_[b];
      const size_t ka = static_cast<size_t>(a);
      // A non-finite request or state gives a non-finite torque, which the rollout reports
      // as an instability (MuJoCo's bad-ctrl warning) rather than a quiet zero.
      torque_[ka] = t;
      const double ratio = std::fabs(torque_[ka]) / joints_[ka].limit;
      if (ratio > worst_ratio) {
        worst_ratio = ratio;
        worst = a;
      }
    }
    if (worst < 0) break;
    const size_t kw = static_cast<size_t>(worst);
    torque_[kw] = std::clamp(torque_[kw], -joints_[kw].limit, joints_[kw].limit);
    free_.erase(std::find(free_.begin(), free_.end(), worst));
    // The held torque moves to the right-hand side of the others' equations ...
    for (int a : free_) rhs_[a] -= system_(a, worst) * torque_[kw];
    // ... and the free joints' inverse loses the held one (Schur complement), or is
    // computed afresh should its pivot vanish.
    const double pivot = inverse_(worst, worst);
    if (std::isfinite(pivot) && pivot != 0) {
      for (int a : free_)
        for (int b : free_) inverse_(a, b) -= inverse_(a, worst) * inverse_(worst, b) / pivot;
    } else if (!free_.empty()) {
      const auto f = static_cast<Eigen::Index>(free_.size());
      Eigen::MatrixXd reduced(f, f);
      for (Eigen::Index a = 0; a < f; ++a)
        for (Eigen::Index b = 0; b < f; ++b) reduced(a, b) = system_(free_[static_cast<size_t>(a)], free_[static_cast<size_t>(b)]);
      const Eigen::MatrixXd inv = reduced.partialPivLu().inverse();
      for (Eigen::Index a = 0; a < f; ++a)
        for (Eigen::Index b = 0; b < f; ++b) inverse_(free_[static_cast<size_t>(a)], free_[static_cast<size_t>(b)]) = inv(a, b);
    }
  }
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
