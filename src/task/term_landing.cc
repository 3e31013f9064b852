#include "task/term_landing.h"

#include <algorithm>
#include <cmath>

#include "core/toml_reader.h"
#include "task/constraints.h"
#include "task/task.h"

namespace diverse {

void read_landing(const TomlReader& r, const Task& task, TaskConstraints& c) {
  (void)task;
  r.only({"center", "half_width", "lateral", "radius", "weight"});
  auto t = std::make_shared<LandingConstraint>(r.path());
  t->center = r.number("center", -20, 20);
  if (r.has("radius")) {
    if (r.has("half_width")) r.fail("radius", "expected either half_width (a box along x) or radius (a disc), not both");
    t->radius = r.number("radius", 0.001, 10);
    t->lateral = r.number("lateral", -20, 20, 0.0);
  } else {
    if (r.has("lateral")) r.fail("lateral", "expected lateral only with a radius (a disc)");
    t->half_width = r.number("half_width", 0.001, 10);
  }
  t->weight = term_weight(r, c);
  c.terms.push_back(std::move(t));
}

void LandingConstraint::penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const {
  (void)task;
  double d = 0;
  if (radius > 0) {
    const double touchdown = std::hypot(motion.touchdown_feet_x - center, motion.touchdown_feet_y - lateral);
    const double rest = std::hypot(motion.feet_x - center, motion.feet_y - lateral);
    d = std::max(0.0, std::max(touchdown, rest) - radius);
  } else {
    auto outside = [&](double x) { return std::max(0.0, std::fabs(x - center) - half_width); };
    d = std::max(outside(motion.touchdown_feet_x), outside(motion.feet_x));
  }
  report.add("landing", d, weight * d * d);
}

double LandingConstraint::margin(const Task& task, const MotionSummary& motion) const {
  (void)task;
  if (radius > 0) {
    return std::min(radius - std::hypot(motion.touchdown_feet_x - center, motion.touchdown_feet_y - lateral),
                    radius - std::hypot(motion.feet_x - center, motion.feet_y - lateral));
  }
  return std::min(half_width - std::fabs(motion.touchdown_feet_x - center),
                  half_width - std::fabs(motion.feet_x - center));
}

std::optional<std::pair<double, double>> LandingConstraint::feet_x_range(const Task& task) const {
  (void)task;
  const double half = radius > 0 ? radius : half_width;
  return std::make_pair(center - half, center + half);
}

}  // namespace diverse
