#include "physics/centroidal.h"

#include <stdexcept>

namespace diverse {

CentroidalPitchOf::CentroidalPitchOf(const mjModel* m, int root) {
  if (root < 0 || root >= m->nbody) throw std::invalid_argument("CentroidalPitchOf: no such body");
  std::vector<char> inside(static_cast<size_t>(m->nbody), 0);
  inside[static_cast<size_t>(root)] = 1;
  bodies_.push_back(root);
  for (int b = root + 1; b < m->nbody; ++b) {  // a parent's id is below its children's
    if (inside[static_cast<size_t>(m->body_parentid[b])]) {
      inside[static_cast<size_t>(b)] = 1;
      bodies_.push_back(b);
    }
  }
}

CentroidalPitch CentroidalPitchOf::operator()(const mjModel* m, const mjData* d, const double* com,
                                               const double* com_velocity) const {
  CentroidalPitch out;
  double ly = 0;
  for (int b : bodies_) {
    const mjtNum* c = d->cvel + 6 * b;  // [angular; linear at the tree's COM], world axes
    const mjtNum* r = d->xipos + 3 * b;
    const mjtNum* from = d->subtree_com + 3 * m->body_rootid[b];
    const double dif[3] = {r[0] - from[0], r[1] - from[1], r[2] - from[2]};
    // The body's COM velocity: the linear part moved to the body's COM.
    const double vx = c[3] - (dif[1] * c[2] - dif[2] * c[1]);
    const double vz = c[5] - (dif[0] * c[1] - dif[1] * c[0]);
    const double rx = r[0] - com[0], rz = r[2] - com[2];
    const double mass = m->body_mass[b];
    // The body's inertia about the world y axis: R diag(I) R^T, its yy entry.
    const mjtNum* R = d->ximat + 9 * b;
    const mjtNum* I = m->body_inertia + 3 * b;
    const double iyy = R[3] * R[3] * I[0] + R[4] * R[4] * I[1] + R[5] * R[5] * I[2];
    // (r x m v)_y = m (rz vx - rx vz), relative to the COM and its velocity.
    ly += iyy * c[1] + mass * (rz * (vx - com_velocity[0]) - rx * (vz - com_velocity[2]));
    out.inertia += iyy + mass * (rx * rx + rz * rz);
  }
  out.momentum = -ly;
  return out;
}

}  // namespace diverse
