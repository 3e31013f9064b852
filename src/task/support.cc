#include "task/support.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/polygon.h"

namespace diverse {

double capture_point_margin(const mjModel* m, const mjData* d, const Character& body,
                            const std::array<double, 3>& com, const std::array<double, 3>& com_velocity) {
  // The feet's contacts: their mean height, and for the planar character the x-interval
  // they span (nothing allocated on this path, which runs every step of a slow landing).
  int count = 0;
  double ground_z = 0, lo = 0, hi = 0;
  auto foot_contact = [&](const mjContact& c) {
    return c.exclude == 0 && (body.is_foot_geom(m, c.geom1) || body.is_foot_geom(m, c.geom2));
  };
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    if (!foot_contact(c)) continue;
    lo = count == 0 ? c.pos[0] : std::min(lo, c.pos[0]);
    hi = count == 0 ? c.pos[0] : std::max(hi, c.pos[0]);
    ground_z += c.pos[2];
    ++count;
  }
  if (count == 0) return -std::numeric_limits<double>::infinity();
  ground_z /= count;
  const double g = std::max(1e-9, std::fabs(m->opt.gravity[2]));
  const double time_constant = std::sqrt(std::max(0.0, com[2] - ground_z) / g);
  const Vec2 cp{com[0] + com_velocity[0] * time_constant, com[1] + com_velocity[1] * time_constant};
  if (body.root == RootKind::kPlanar) return std::min(cp[0] - lo, hi - cp[0]);
  std::vector<Vec2> points;
  points.reserve(static_cast<size_t>(count));
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    if (foot_contact(c)) points.push_back({c.pos[0], c.pos[1]});
  }
  return polygon_margin(convex_hull(std::move(points)), cp);
}

SoleOutline sole_outline(const mjModel* m, const mjData* d, const Character& body, const ContactState& contacts) {
  std::vector<Vec2> points;
  for (int g = 0; g < m->ngeom; ++g) {
    int foot = -1;
    if (!body.is_foot_geom(m, g, &foot) || !contacts.foot[static_cast<size_t>(foot)]) continue;
    const double* x = d->geom_xpos + 3 * g;
    const double* R = d->geom_xmat + 9 * g;  // columns: the geom's axes in the world
    const double* size = m->geom_size + 3 * g;
    const int type = m->geom_type[g];
    auto square = [&](double r) {
      for (int c = 0; c < 4; ++c) points.push_back({x[0] + (c & 1 ? 1 : -1) * r, x[1] + (c & 2 ? 1 : -1) * r});
    };
    if (type == mjGEOM_CAPSULE || type == mjGEOM_CYLINDER) {
      // The axis (local z) projected on the ground, lengthened by the radius each way: a
      // capsule reaches size[1] |axis_xy| + radius from its centre along it.
      const double ax = R[2], ay = R[5];
      const double flat = std::hypot(ax, ay);
      const double stretch = type == mjGEOM_CAPSULE && flat > 1e-9 ? size[0] / flat : 0;
      for (double end : {-1.0, 1.0}) {
        const double k = end * (size[1] + stretch);
        points.push_back({x[0] + k * ax, x[1] + k * ay});
      }
      if (type == mjGEOM_CYLINDER || flat <= 1e-9) square(size[0]);
    } else if (type == mjGEOM_BOX) {
      for (int c = 0; c < 8; ++c) {
        const double l[3] = {(c & 1 ? 1 : -1) * size[0], (c & 2 ? 1 : -1) * size[1], (c & 4 ? 1 : -1) * size[2]};
        double w[3];
        mju_mulMatVec(w, R, l, 3, 3);
        points.push_back({x[0] + w[0], x[1] + w[1]});
      }
    } else {
      square(type == mjGEOM_SPHERE ? size[0] : m->geom_rbound[g]);
    }
  }
  SoleOutline out;
  out.planar = body.root == RootKind::kPlanar;
  if (out.planar) {
    for (size_t i = 0; i < points.size(); ++i) {
      out.lo = i == 0 ? points[i][0] : std::min(out.lo, points[i][0]);
      out.hi = i == 0 ? points[i][0] : std::max(out.hi, points[i][0]);
    }
  } else {
    out.hull = convex_hull(std::move(points));
  }
  return out;
}

double SoleOutline::margin(const Vec2& p) const {
  if (planar) return lo <= hi ? std::min(p[0] - lo, hi - p[0]) : -std::numeric_limits<double>::infinity();
  return polygon_margin(hull, p);  // -infinity for an empty hull
}

}  // namespace diverse
