#include "physics/com_velocity.h"

#include <stdexcept>

namespace diverse {

SubtreeComVelocity::SubtreeComVelocity(const mjModel* m, int root)
    : root_(root), momentum_(3 * static_cast<size_t>(m->nbody)) {
  if (root < 0 || root >= m->nbody) throw std::invalid_argument("SubtreeComVelocity: no such body");
  // MuJoCo orders bodies so that a parent's id is below its children's: one pass finds
  // the subtree.
  std::vector<char> inside(static_cast<size_t>(m->nbody), 0);
  inside[static_cast<size_t>(root)] = 1;
  bodies_.push_back(root);
  for (int b = root + 1; b < m->nbody; ++b) {
    if (inside[static_cast<size_t>(m->body_parentid[b])]) {
      inside[static_cast<size_t>(b)] = 1;
      bodies_.push_back(b);
    }
  }
}

std::array<double, 3> SubtreeComVelocity::operator()(const mjModel* m, const mjData* d) {
  for (int b : bodies_) {
    // mj_objectVelocity(m, d, mjOBJ_BODY, b, ., 0), linear part only: the body's spatial
    // velocity cvel moved from its tree's centre of mass to its own (mju_transformSpatial,
    // whose mju_sub3 and mju_cross are these lines, term by term; C++ is compiled in ISO
    // mode, -std=c++20, which contracts no multiply-add into an FMA).
    const mjtNum* c = d->cvel + 6 * b;
    const mjtNum* to = d->xipos + 3 * b;
    const mjtNum* from = d->subtree_com + 3 * m->body_rootid[b];
    const mjtNum dif[3] = {to[0] - from[0], to[1] - from[1], to[2] - from[2]};
    const mjtNum cross[3] = {dif[1] * c[2] - dif[2] * c[1], dif[2] * c[0] - dif[0] * c[2],
                             dif[0] * c[1] - dif[1] * c[0]};
    const mjtNum linear[3] = {c[3] - cross[0], c[4] - cross[1], c[5] - cross[2]};
    mju_scl3(momentum_.data() + 3 * b, linear, m->body_mass[b]);
  }
  // Children into parents, highest id first: the order of mj_subtreeVel's sums.
  for (size_t k = bodies_.size(); k-- > 1;) {
    const int b = bodies_[k];
    mju_addTo3(momentum_.data() + 3 * m->body_parentid[b], momentum_.data() + 3 * b);
  }
  mjtNum* p = momentum_.data() + 3 * root_;
  mju_scl3(p, p, 1 / mjMAX(mjMINVAL, m->body_subtreemass[root_]));
  return {p[0], p[1], p[2]};
}

}  // namespace diverse
