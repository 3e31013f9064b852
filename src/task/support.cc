#include "task/support.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace diverse {
namespace {

struct Point {
  double x, y;
};

double cross(const Point& o, const Point& a, const Point& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// Convex hull, counter-clockwise, without collinear points (Andrew's monotone chain).
std::vector<Point> convex_hull(std::vector<Point> p) {
  std::sort(p.begin(), p.end(), [](const Point& a, const Point& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  if (p.size() < 3) return p;
  std::vector<Point> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

double segment_distance(const Point& q, const Point& a, const Point& b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((q.x - a.x) * dx + (q.y - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(q.x - a.x - t * dx, q.y - a.y - t * dy);
}

// Signed distance from q to the boundary of the convex polygon h (counter-clockwise):
// positive inside. A hull of one or two points is a point or a segment: never inside.
double polygon_margin(const Point& q, const std::vector<Point>& h) {
  if (h.size() == 1) return -std::hypot(q.x - h[0].x, q.y - h[0].y);
  double nearest = std::numeric_limits<double>::infinity();
  bool inside = h.size() >= 3;
  for (size_t i = 0; i < h.size(); ++i) {
    const Point& a = h[i];
    const Point& b = h[(i + 1) % h.size()];
    nearest = std::min(nearest, segment_distance(q, a, b));
    if (cross(a, b, q) < 0) inside = false;
    if (h.size() == 2) break;
  }
  return inside ? nearest : -nearest;
}

}  // namespace

double capture_point_margin(const mjModel* m, const mjData* d, const Character& body,
                            const std::array<double, 3>& com, const std::array<double, 3>& com_velocity) {
  std::vector<Point> contacts;
  double ground_z = 0;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    if (c.exclude != 0) continue;  // in the margin gap: near, not touching
    if (!body.is_foot_geom(m, c.geom1) && !body.is_foot_geom(m, c.geom2)) continue;
    contacts.push_back({c.pos[0], c.pos[1]});
    ground_z += c.pos[2];
  }
  if (contacts.empty()) return -std::numeric_limits<double>::infinity();
  ground_z /= static_cast<double>(contacts.size());
  const double g = std::max(1e-9, std::fabs(m->opt.gravity[2]));
  const double time_constant = std::sqrt(std::max(0.0, com[2] - ground_z) / g);
  const Point cp{com[0] + com_velocity[0] * time_constant, com[1] + com_velocity[1] * time_constant};
  if (body.root == RootKind::kPlanar) {
    double lo = contacts[0].x, hi = contacts[0].x;
    for (const Point& p : contacts) lo = std::min(lo, p.x), hi = std::max(hi, p.x);
    return std::min(cp.x - lo, hi - cp.x);
  }
  return polygon_margin(cp, convex_hull(std::move(contacts)));
}

}  // namespace diverse
