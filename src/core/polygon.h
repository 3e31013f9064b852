// Convex polygons in the ground plane: the support polygon of a character's feet (the
// stance controller's centre-of-pressure limit, control/stance_controller.h; whether a
// landing is balanced, task/support.h).
#pragma once

#include <array>
#include <vector>

namespace diverse {

using Vec2 = std::array<double, 2>;

// (a - o) x (b - o): positive when o, a, b turn counter-clockwise.
double cross2(const Vec2& o, const Vec2& a, const Vec2& b);

// Convex hull, counter-clockwise, no repeated end point (Andrew's monotone chain). Points
// are rounded to 1 micrometre and vertices on a straight edge dropped.
std::vector<Vec2> convex_hull(std::vector<Vec2> p);

// The convex polygon `h` (counter-clockwise) eroded by `margin`; if nothing is left, the
// centroid of `h` alone.
std::vector<Vec2> shrink(const std::vector<Vec2>& h, double margin);

// The point of the convex polygon `h` (counter-clockwise) nearest to p.
Vec2 project(const std::vector<Vec2>& h, const Vec2& p);

// The signed distance from p to the boundary of the convex polygon h (counter-clockwise):
// positive inside, negative outside; a hull of one or two points is never inside, and an
// empty one is -infinity away.
double polygon_margin(const std::vector<Vec2>& h, const Vec2& p);

}  // namespace diverse
