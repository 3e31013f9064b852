#include "toy/toy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace diverse {
namespace {

double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

std::string num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f", v);
  return buffer;
}

}  // namespace

ToyRegion default_toy_region() {
  ToyRegion region;
  // Tips right, top, left, bottom; the reflex vertices between them sit 0.15 off the
  // centre on the diagonals.
  region.polygon = {{0.95, 0.50}, {0.65, 0.65}, {0.50, 0.80}, {0.35, 0.65},
                    {0.05, 0.50}, {0.35, 0.35}, {0.50, 0.20}, {0.65, 0.35}};
  region.reference = {0.5, 0.5};
  return region;
}

bool toy_inside(const ToyRegion& region, const Eigen::Vector2d& p) {
  bool inside = false;
  const auto& poly = region.polygon;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

double toy_outside_distance(const ToyRegion& region, const Eigen::Vector2d& p) {
  if (toy_inside(region, p)) return 0.0;
  double d = std::numeric_limits<double>::infinity();
  const auto& poly = region.polygon;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    d = std::min(d, segment_distance(p, poly[j], poly[i]));
  }
  return d;
}

double toy_max_reach(const ToyRegion& region) {
  double r = 0.0;
  for (const auto& v : region.polygon) r = std::max(r, (v - region.reference).norm());
  return r;
}

ToyProblem::ToyProblem(ToyRegion region, double penalty)
    : region_(std::move(region)), penalty_(penalty) {
  if (region_.polygon.size() < 3) throw std::invalid_argument("ToyProblem: polygon needs 3 vertices");
  if (!toy_inside(region_, region_.reference)) {
    throw std::invalid_argument("ToyProblem: the reference point must lie inside the region");
  }
}

std::shared_ptr<const Outcome> ToyProblem::evaluate(const Eigen::VectorXd& x, int) const {
  auto outcome = std::make_shared<ToyOutcome>();
  outcome->point = x.head<2>();
  const double e = toy_outside_distance(region_, outcome->point);
  outcome->constraint = penalty_ * e * e;
  return outcome;
}

double ToyProblem::distance(const Outcome& a, const Outcome& b) const {
  const auto& pa = static_cast<const ToyOutcome&>(a).point;
  const auto& pb = static_cast<const ToyOutcome&>(b).point;
  return (pa - pb).squaredNorm();
}

ToyFigures toy_figures(const ToyRegion& region, const std::vector<Eigen::Vector2d>& points) {
  ToyFigures f;
  if (points.empty()) return f;
  double reach = 0.0;
  for (const auto& p : points) reach += (p - region.reference).norm();
  f.reach = reach / static_cast<double>(points.size()) / toy_max_reach(region);
  if (points.size() < 2) return f;
  double smallest = std::numeric_limits<double>::infinity(), sum = 0.0;
  int pairs = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = i + 1; j < points.size(); ++j) {
      const double d = (points[i] - points[j]).norm();
      smallest = std::min(smallest, d);
      sum += d;
      ++pairs;
    }
  }
  const double mean = sum / pairs;
  f.clustering = mean > 0.0 ? smallest / mean : 0.0;
  return f;
}

std::string toy_svg(const ToyRegion& region, const std::vector<Eigen::Vector2d>& points,
                    const std::vector<std::vector<Eigen::Vector2d>>& paths,
                    const std::string& title) {
  // The unit box drawn 400 px wide with a 40 px margin, y up.
  const double scale = 400.0, margin = 40.0, size = scale + 2 * margin;
  auto px = [&](const Eigen::Vector2d& p) {
    return num(margin + scale * p.x()) + "," + num(margin + scale * (1.0 - p.y()));
  };
  static const char* colors[] = {"#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e",
                                 "#8c564b", "#e377c2", "#17becf", "#bcbd22"};
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << size << "\" height=\""
    << size + 30 << "\" viewBox=\"0 0 " << size << " " << size + 30 << "\">\n";
  s << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"" << margin << "\" y=\"" << size + 18
    << "\" font-family=\"sans-serif\" font-size=\"14\">" << title << "</text>\n";
  s << "<rect x=\"" << margin << "\" y=\"" << margin << "\" width=\"" << scale << "\" height=\""
    << scale << "\" fill=\"none\" stroke=\"#bbbbbb\" stroke-dasharray=\"4 4\"/>\n";
  s << "<polygon points=\"";
  for (const auto& v : region.polygon) s << px(v) << " ";
  s << "\" fill=\"#dbe9f6\" stroke=\"#4a7fb5\" stroke-width=\"2\"/>\n";
  for (std::size_t i = 0; i < paths.size(); ++i) {
    if (paths[i].size() < 2) continue;
    s << "<polyline points=\"";
    for (const auto& p : paths[i]) s << px(p) << " ";
    s << "\" fill=\"none\" stroke=\"" << colors[i % 8]
      << "\" stroke-width=\"1\" stroke-opacity=\"0.6\"/>\n";
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::string c = px(points[i]);
    const auto comma = c.find(',');
    const std::string x = c.substr(0, comma), y = c.substr(comma + 1);
    s << "<circle cx=\"" << x << "\" cy=\"" << y << "\" r=\"7\" fill=\"" << colors[i % 8]
      << "\" stroke=\"black\"/>\n";
    s << "<text x=\"" << x << "\" y=\"" << y << "\" dx=\"9\" dy=\"-7\" font-family=\"sans-serif\""
      << " font-size=\"13\">" << i + 1 << "</text>\n";
  }
  const std::string r = px(region.reference);
  const auto comma = r.find(',');
  s << "<circle cx=\"" << r.substr(0, comma) << "\" cy=\"" << r.substr(comma + 1)
    << "\" r=\"7\" fill=\"red\" stroke=\"black\"/>\n";
  s << "</svg>\n";
  return s.str();
}

}  // namespace diverse
