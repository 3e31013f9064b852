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

}  // namespace diverse
