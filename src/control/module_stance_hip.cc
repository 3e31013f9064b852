#include "control/module_stance_hip.h"

#include <algorithm>
#include <cmath>

namespace diverse {
namespace {

double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

}  // namespace

StanceHipModule::StanceHipModule(const ModuleSettings& settings, const Character& body)
    : root_kp_(settings.get("root_kp", 0)), root_kd_(settings.get("root_kd", 0)), layout_(leg_layout(body)) {}

void StanceHipModule::reset(const mjModel* m, const mjData* d, SkillState& s) {
  (void)d;
  if (s.standing == nullptr) return;
  const double gravity = -m->opt.gravity[2];
  if (!(root_kp_ > 0)) root_kp_ = 2 * s.standing->mass * gravity * s.standing->com_height;
  if (!(root_kd_ > 0)) root_kd_ = root_kp_ / 5;
}

void StanceHipModule::adjust_torques(const mjModel* m, const mjData* d, SkillState& s) {
  (void)m;
  if (s.swing < 0 || !s.root || s.standing == nullptr) return;
  const Character& body = *s.body;
  const int swing = s.swing, stance = 1 - swing;
  const bool double_support = s.double_support;
  std::vector<double>& u = s.u;
  std::vector<double>& kd = s.damping;
  const auto& leg_of = layout_.leg_of;
  const auto& hip = layout_.hip;
  auto is_swing_hip = [&](int k) { return hip[static_cast<size_t>(k)] && leg_of[static_cast<size_t>(k)] == swing; };
  auto is_stance_hip = [&](int k) {
    return hip[static_cast<size_t>(k)] && (leg_of[static_cast<size_t>(k)] == stance || (double_support && leg_of[static_cast<size_t>(k)] == swing));
  };
  double target[4], e[3];
  heading_root_target(*s.standing, s.heading, s.root_pitch, s.root_roll, target);
  rotation_error(target, d->xquat + 4 * body.root_body, e);
  double base[3], swing_part[3] = {0, 0, 0};
  for (int i = 0; i < 3; ++i) base[i] = root_kp_ * e[i];
  for (int k : layout_.root_children) {
    if (is_stance_hip(k)) continue;
    const CharacterJoint& j = body.joints[static_cast<size_t>(k)];
    const double tau = std::clamp(u[static_cast<size_t>(k)] - kd[static_cast<size_t>(k)] * d->qvel[j.dof], -j.torque_limit, j.torque_limit);
    const double* a = d->xaxis + 3 * j.joint;
    double* sum = is_swing_hip(k) ? swing_part : base;
    for (int i = 0; i < 3; ++i) sum[i] += tau * a[i];
  }
  const double share = double_support ? 0.5 : 1.0;
  double scale = 1;
  for (int k : layout_.root_children) {
    if (!is_stance_hip(k)) continue;
    const CharacterJoint& j = body.joints[static_cast<size_t>(k)];
    const double* a = d->xaxis + 3 * j.joint;
    const double* w_child = d->cvel + 6 * j.body;
    const double fixed = share * (-dot3(a, base) + root_kd_ * dot3(a, w_child) - root_kd_ * d->qvel[j.dof]);
    const double varying = -share * dot3(a, swing_part);
    const double L = j.torque_limit;
    if (std::fabs(fixed + varying) <= L) continue;
    if (std::fabs(fixed) >= L) {
      scale = 0;
    } else {
      // |fixed + s varying| = L at s = (sign(varying) L - fixed) / varying.
      const double bound = ((varying > 0 ? L : -L) - fixed) / varying;
      scale = std::min(scale, std::clamp(bound, 0.0, 1.0));
    }
  }
  for (int k : layout_.root_children) {
    if (!is_swing_hip(k) || is_stance_hip(k)) continue;
    u[static_cast<size_t>(k)] *= scale;
    kd[static_cast<size_t>(k)] *= scale;
  }
  for (int k : layout_.root_children) {
    if (!is_stance_hip(k)) continue;
    const CharacterJoint& j = body.joints[static_cast<size_t>(k)];
    const double* a = d->xaxis + 3 * j.joint;
    const double* w_child = d->cvel + 6 * j.body;
    double torque[3];
    for (int i = 0; i < 3; ++i) torque[i] = base[i] + scale * swing_part[i];
    u[static_cast<size_t>(k)] = share * (-dot3(a, torque) + root_kd_ * dot3(a, w_child));
    kd[static_cast<size_t>(k)] = share * root_kd_;
  }
}

}  // namespace diverse
