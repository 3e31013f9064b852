#include "control/module_simbicon.h"

#include <cmath>

namespace diverse {

SimbiconModule::SimbiconModule(const SkillModuleSpec& spec, const ModuleSettings& settings, const Character& body)
    : coronal_(spec.words.at("plane") == "coronal"), cd_(settings.get("cd", 0)), cv_(settings.get("cv", 0)) {
  const LegLayout l = leg_layout(body);
  for (size_t k = 0; k < body.joints.size(); ++k) {
    if (!l.hip[k]) continue;
    const JointPlane plane = body.groups[static_cast<size_t>(body.joints[k].group)].plane;
    if ((plane == JointPlane::kCoronal) == coronal_) hips_[static_cast<size_t>(l.leg_of[k])].push_back(static_cast<int>(k));
  }
}

void SimbiconModule::set_targets(const mjModel* m, const mjData* d, SkillState& s) {
  if (s.swing < 0) return;
  const Character& body = *s.body;
  // The COM velocity: the links' momenta over the mass (once a step for every module).
  if (s.link_com_vel_time != s.time) {
    double p[3] = {0, 0, 0};
    for (int b : body.links) {
      const double* v = d->cvel + 6 * b;
      const double* o = d->subtree_com + 3 * m->body_rootid[b];
      const double r[3] = {d->xipos[3 * b] - o[0], d->xipos[3 * b + 1] - o[1], d->xipos[3 * b + 2] - o[2]};
      double w_r[3];
      mju_cross(w_r, v, r);
      for (int i = 0; i < 3; ++i) p[i] += m->body_mass[b] * (v[3 + i] + w_r[i]);
    }
    const double mass = m->body_subtreemass[body.root_body];
    for (size_t i = 0; i < 3; ++i) s.link_com_vel[i] = p[i] / mass;
    s.link_com_vel_time = s.time;
  }
  const double* vel = s.link_com_vel.data();

  const int swing = s.swing, stance = 1 - swing;
  const double ch = std::cos(s.heading), sh = std::sin(s.heading);
  const double* ankle = d->xpos + 3 * body.feet[static_cast<size_t>(stance)];
  const double dx = s.com[0] - ankle[0], dy = s.com[1] - ankle[1];
  double feedback = 0;
  if (coronal_) {
    const double toward_swing = swing == 0 ? 1.0 : -1.0;  // the heading frame's y points left
    const double dc = toward_swing * (-sh * dx + ch * dy);
    const double vc = toward_swing * (-sh * vel[0] + ch * vel[1]);
    feedback = cd_ * dc + cv_ * vc;
  } else {
    const double ds = ch * dx + sh * dy;
    const double vs = ch * vel[0] + sh * vel[1];
    feedback = cd_ * ds + cv_ * vs;
  }
  for (int k : hips_[static_cast<size_t>(swing)]) s.target[static_cast<size_t>(k)] += feedback;
}

}  // namespace diverse
