#include "physics/drive.h"

#include <algorithm>
#include <cmath>
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

JointDrive::JointDrive(std::vector<DrivenJoint> joints, SaturatedDrive saturated)
    : joints_(std::move(joints)),
      saturated_(saturated),
      u_(joints_.size(), 0.0),
      kd_(joints_.size(), 0.0),
      qdot_(joints_.size(), 0.0),
      explicit_(joints_.size(), 0) {
  for (const DrivenJoint& j : joints_) dofs_.push_back(j.dof);
}

bool JointDrive::apply(mjModel* m, mjData* d) {
  ++counts_.steps;
  redone_ = false;
  bool damping_changed = false;
  for (size_t k = 0; k < joints_.size(); ++k) {
    const DrivenJoint& j = joints_[k];
    const double u = u_[k], kd = kd_[k], qdot = d->qvel[j.dof];
    qdot_[k] = qdot;
    const double request = u - kd * qdot;
    // Implicit only while neither the motor (ctrl = u) nor the request is saturated: a
    // saturated request is exactly what the explicit way delivers, and implicit damping
    // on top of a clamped motor is what broke the limit before.
    const bool implicit = std::fabs(u) <= j.limit && std::fabs(request) <= j.limit;
    explicit_[k] = implicit ? 0 : 1;
    d->ctrl[j.actuator] = implicit ? u : explicit_torque(m, d, k, qdot);
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

void JointDrive::make_explicit(mjModel* m, mjData* d, size_t k) {
  const DrivenJoint& j = joints_[k];
  explicit_[k] = 1;
  d->ctrl[j.actuator] = explicit_torque(m, d, k, qdot_[k]);
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
