#include "core/polygon.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace diverse {

double cross2(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// Convex hull, counter-clockwise, no repeated end point (Andrew's monotone chain). Points
// are rounded to 1 micrometre and vertices on a straight edge dropped, so a box's top and
// bottom corners (the same points up to rounding) give one clean polygon.
std::vector<Vec2> convex_hull(std::vector<Vec2> p) {
  for (Vec2& v : p) {
    for (double& x : v) x = std::round(x * 1e6) * 1e-6;
  }
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  std::vector<Vec2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross2(h[k - 2], h[k - 1], p[i]) <= 1e-10) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(h[k - 2], h[k - 1], p[i]) <= 1e-10) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

// The convex polygon `h` (counter-clockwise) eroded by `margin`: clipped by each edge's
// half-plane shifted `margin` inward (Sutherland-Hodgman), which stays right however short
// the edges are. If nothing is left, the centroid of `h` alone.
std::vector<Vec2> shrink(const std::vector<Vec2>& h, double margin) {
  const size_t n = h.size();
  Vec2 centroid{0, 0};
  for (const Vec2& v : h) {
    centroid[0] += v[0] / static_cast<double>(n);
    centroid[1] += v[1] / static_cast<double>(n);
  }
  if (n < 3) return {centroid};
  std::vector<Vec2> poly = h, next;
  for (size_t i = 0; i < n && !poly.empty(); ++i) {
    const Vec2& a = h[i];
    const Vec2& b = h[(i + 1) % n];
    const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
    if (len < 1e-9) continue;
    const Vec2 normal{-(b[1] - a[1]) / len, (b[0] - a[0]) / len};  // inward: left of a->b
    const double c = normal[0] * a[0] + normal[1] * a[1] + margin;
    next.clear();
    for (size_t k = 0; k < poly.size(); ++k) {
      const Vec2& p = poly[k];
      const Vec2& q = poly[(k + 1) % poly.size()];
      const double dp = normal[0] * p[0] + normal[1] * p[1] - c;
      const double dq = normal[0] * q[0] + normal[1] * q[1] - c;
      if (dp >= 0) next.push_back(p);
      if ((dp >= 0) != (dq >= 0)) {
        const double t = dp / (dp - dq);
        next.push_back({p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])});
      }
    }
    poly.swap(next);
  }
  if (poly.size() < 3) return {centroid};
  return poly;
}

// The point of the convex polygon `h` (counter-clockwise) nearest to p.
Vec2 project(const std::vector<Vec2>& h, const Vec2& p) {
  if (h.size() == 1) return h[0];
  bool inside = h.size() >= 3;
  for (size_t i = 0; i < h.size() && inside; ++i) {
    if (cross2(h[i], h[(i + 1) % h.size()], p) < 0) inside = false;
  }
  if (inside) return p;
  Vec2 best = h[0];
  double best_d = INFINITY;
  for (size_t i = 0; i < h.size(); ++i) {
    const Vec2& a = h[i];
    const Vec2& b = h[(i + 1) % h.size()];
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2 : 0;
    t = std::clamp(t, 0.0, 1.0);
    const Vec2 q{a[0] + t * dx, a[1] + t * dy};
    const double dist = std::hypot(p[0] - q[0], p[1] - q[1]);
    if (dist < best_d) {
      best_d = dist;
      best = q;
    }
  }
  return best;
}

// The signed distance from p to the boundary of the convex polygon h (counter-clockwise):
// positive inside, negative outside; a hull of one or two points is never inside.
double polygon_margin(const std::vector<Vec2>& h, const Vec2& p) {
  if (h.empty()) return -std::numeric_limits<double>::infinity();
  const Vec2 q = project(h, p);
  const double to_q = std::hypot(p[0] - q[0], p[1] - q[1]);
  if (to_q > 0 || h.size() < 3) return -to_q;
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < h.size(); ++i) {
    const Vec2& a = h[i];
    const Vec2& b = h[(i + 1) % h.size()];
    const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
    if (len > 0) nearest = std::min(nearest, cross2(a, b, p) / len);
  }
  return nearest;
}

}  // namespace diverse
