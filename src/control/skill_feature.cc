#include "control/skill_feature.h"

#include <algorithm>
#include <cmath>

namespace diverse {

const std::vector<std::string>& skill_feature_names() {
  static const std::vector<std::string> names = {"com_x", "com_z", "com_vx", "com_vz", "pitch", "pitch_rate"};
  return names;
}

bool skill_feature_of(const std::string& name, SkillFeature* out) {
  const auto& names = skill_feature_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) return false;
  *out = static_cast<SkillFeature>(it - names.begin());
  return true;
}

namespace {

// A free root's pitch (rad, positive backwards) and pitch rate (rad/s) about the heading
// frame's lateral axis, relative to its orientation in the model's standing pose.
std::array<double, 2> free_root_pitch(const Character& body, const mjModel* m, const mjData* d) {
  double standing_inv[4], q[4];
  mju_negQuat(standing_inv, m->qpos0 + body.root_qpos + 3);
  mju_mulQuat(q, d->xquat + 4 * body.root_body, standing_inv);
  double up[3];
  const double z[3] = {0, 0, 1};
  mju_rotVecQuat(up, z, q);
  // The heading: the forward axis turned onto the ground (up straight, the x axis).
  double fwd[3];
  const double x[3] = {1, 0, 0};
  mju_rotVecQuat(fwd, x, q);
  const double h = std::atan2(fwd[1], fwd[0]);
  const double ch = std::cos(h), sh = std::sin(h);
  const double along = up[0] * ch + up[1] * sh;  // the up axis leaning forward
  const double pitch = std::atan2(-along, up[2]);
  // Turning backwards is a turn about the heading's right (-y_h) axis.
  const double* w = d->cvel + 6 * body.root_body;
  const double rate = -(-sh * w[0] + ch * w[1]);
  return {pitch, rate};
}

}  // namespace

double skill_feature(SkillFeature f, const Character& body, const mjModel* m, const mjData* d,
                     const std::array<double, 3>& com, const std::array<double, 3>& com_vel) {
  switch (f) {
    case SkillFeature::kComX: return com[0];
    case SkillFeature::kComZ: return com[2];
    case SkillFeature::kComVx: return com_vel[0];
    case SkillFeature::kComVz: return com_vel[2];
    case SkillFeature::kPitch:
      return body.root == RootKind::kFree ? free_root_pitch(body, m, d)[0] : d->qpos[body.root_pitch_qpos];
    case SkillFeature::kPitchRate:
      return body.root == RootKind::kFree ? free_root_pitch(body, m, d)[1] : d->qvel[body.root_pitch_dof];
  }
  return 0;
}

}  // namespace diverse
