// Convex polygons in the ground plane (core/polygon.h): the hull drops interior and
// collinear points, and the signed margin is the distance to the nearest edge, positive
// inside; a point or a segment holds nothing inside.
#include <gtest/gtest.h>

#include <cmath>

#include "core/polygon.h"

namespace diverse {
namespace {

TEST(Polygon, HullOfASquareWithInteriorAndEdgePoints) {
  const std::vector<Vec2> h = convex_hull({{0, 0}, {2, 0}, {1, 0}, {2, 1}, {0, 1}, {1, 0.5}});
  ASSERT_EQ(h.size(), 4u);
  for (size_t i = 0; i < h.size(); ++i) EXPECT_GT(cross2(h[i], h[(i + 1) % 4], h[(i + 2) % 4]), 0);
}

TEST(Polygon, SignedMarginInsideAndOutside) {
  const std::vector<Vec2> square = convex_hull({{0, 0}, {2, 0}, {2, 1}, {0, 1}});
  EXPECT_NEAR(polygon_margin(square, {1, 0.5}), 0.5, 1e-12);
  EXPECT_NEAR(polygon_margin(square, {1.9, 0.5}), 0.1, 1e-12);
  EXPECT_NEAR(polygon_margin(square, {3, 0.5}), -1.0, 1e-12);
  EXPECT_NEAR(polygon_margin(square, {3, 2}), -std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(polygon_margin(convex_hull({{0, 0}, {2, 0}}), {1, 0}), 0.0, 1e-12);
  EXPECT_NEAR(polygon_margin(convex_hull({{0, 0}, {2, 0}}), {1, 0.3}), -0.3, 1e-12);
  EXPECT_NEAR(polygon_margin({{0, 0}}, {0, 0.4}), -0.4, 1e-12);
  EXPECT_EQ(polygon_margin({}, {0, 0}), -INFINITY);
}

}  // namespace
}  // namespace diverse
