// The 2-D toy domain of the paper's figure 2: diversity optimization of points.
//
// Agrawal, Shen, van de Panne, "Diverse Motions and Character Shapes for Simulated
// Skills", IEEE TVCG 2014, section 3, figure 2: N = 4 points start at a reference point
// inside a non-convex feasible region; the distance is the squared Euclidean distance.
// The paper reports that K = 0 clusters the points at extremes of the region, K = 100
// spreads them but stops short of the extremes, and K = 10 gets both. What our runs show
// is in docs/guide/toy.md.
//
// Our region (the paper does not give its shape) is a four-pointed star centred on the
// reference point: two long spikes reaching 0.45 left and right, two short ones reaching
// 0.3 up and down, with reflex vertices 0.15 off the centre on the diagonals. The long
// tips are the region's extremes, where K = 0 piles the points up; the four tips are four
// well separated far places for K = 10 to spread over. (An L with the reference in the
// elbow, or a crescent with it on the back, has only two extremes: there K = 10 keeps two
// points at the ends and two beside the reference; see docs/guide/toy.md.) Parameters are the
// point's coordinates, already in [0, 1]^2, so normalized and domain coordinates coincide.
// The constraint is the paper's quadratic penalty (SPEC 2.4): C = 5000 |e|^2, e the
// Euclidean distance from the point to the region (0 inside).
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "optimize/objective.h"

namespace diverse {

struct ToyRegion {
  std::vector<Eigen::Vector2d> polygon;  // simple polygon, counter-clockwise, in [0, 1]^2
  Eigen::Vector2d reference;             // the reference point P_0, inside the polygon
};

// The L-shaped region described above.
ToyRegion default_toy_region();

// Even-odd test; points on the boundary may go either way (their distance is 0 anyway).
bool toy_inside(const ToyRegion& region, const Eigen::Vector2d& p);
// Euclidean distance from p to the region, 0 inside.
double toy_outside_distance(const ToyRegion& region, const Eigen::Vector2d& p);
// Largest Euclidean distance from the reference to a point of the region (attained at a
// vertex: distance is convex and the region is a union of triangles of its vertices).
double toy_max_reach(const ToyRegion& region);

struct ToyOutcome : Outcome {
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
};

class ToyProblem : public DiversityProblem {
 public:
  explicit ToyProblem(ToyRegion region = default_toy_region(), double penalty = 5000.0);

  int dim() const override { return 2; }
  Eigen::VectorXd reference() const override { return region_.reference; }
  std::shared_ptr<const Outcome> evaluate(const Eigen::VectorXd& x, int worker) const override;
  // Squared Euclidean distance between the two points.
  double distance(const Outcome& a, const Outcome& b) const override;

  const ToyRegion& region() const { return region_; }
  double penalty() const { return penalty_; }

 private:
  ToyRegion region_;
  double penalty_;  // K_c in C = K_c |e|^2
};

// Figures of merit for a set of synthesized points (M_0 excluded), Euclidean distances:
//   clustering = smallest pairwise distance / mean pairwise distance (1 = evenly spread,
//                0 = at least two points coincide; needs >= 2 points, else 0);
//   reach      = mean distance from the reference / toy_max_reach (1 = all at the
//                farthest point of the region).
struct ToyFigures {
  double clustering = 0.0;
  double reach = 0.0;
};
ToyFigures toy_figures(const ToyRegion& region, const std::vector<Eigen::Vector2d>& points);

// An SVG picture of the region (blue), the reference (red), the synthesized points
// (labelled 1..N) and, when given, each point's optimization path (paths[i] for point i).
std::string toy_svg(const ToyRegion& region, const std::vector<Eigen::Vector2d>& points,
                    const std::vector<std::vector<Eigen::Vector2d>>& paths,
                    const std::string& title);

}  // namespace diverse
