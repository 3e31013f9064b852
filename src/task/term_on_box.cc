#include "task/term_on_box.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/toml_reader.h"
#include "task/constraints.h"
#include "task/task.h"

namespace diverse {

void require_object(const TomlReader& r, const Task& task, const char* key, const std::string& name,
                    const char* kind) {
  const SceneObject* obj = task.find_object(name);
  if (obj == nullptr || obj->kind != kind) {
    r.fail(key, std::string("expected the name of an object of kind \"") + kind + "\", got \"" + name + "\"");
  }
}

void read_on_box(const TomlReader& r, const Task& task, TaskConstraints& c) {
  r.only({"object", "margin", "weight"});
  auto t = std::make_shared<OnBoxConstraint>(r.path());
  t->object = r.string("object");
  require_object(r, task, "object", t->object, "box");
  t->edge = r.number("margin", 0, 5);
  t->weight = term_weight(r, c);
  c.terms.push_back(std::move(t));
}

const SceneObject& OnBoxConstraint::box(const Task& task) const { return *task.find_object(object); }

void OnBoxConstraint::penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const {
  const SceneObject& b = box(task);
  const double lo = b.x_min + edge, hi = b.x_max - edge;
  auto off = [&](double x, double z) {
    const double dx = std::max({0.0, lo - x, x - hi});
    const double dz = std::max(0.0, b.height - z);
    return std::hypot(dx, dz);
  };
  const double d = std::max(off(motion.touchdown_feet_x, motion.touchdown_feet_z), off(motion.feet_x, motion.feet_z));
  report.add("on_box", d, weight * d * d);
}

double OnBoxConstraint::margin(const Task& task, const MotionSummary& motion) const {
  const SceneObject& b = box(task);
  const double lo = b.x_min + edge, hi = b.x_max - edge;
  double margin = INFINITY;
  for (const double x : {motion.touchdown_feet_x, motion.feet_x}) margin = std::min({margin, x - lo, hi - x});
  return margin;
}

std::optional<std::pair<double, double>> OnBoxConstraint::feet_x_range(const Task& task) const {
  const SceneObject& b = box(task);
  return std::make_pair(b.x_min + edge, b.x_max - edge);
}

void OnBoxConstraint::check(const Task& task) const {
  const SceneObject& b = box(task);
  const double width = b.x_max - b.x_min;
  if (!(2 * edge < width))
    throw_field_error(task.file, field() + ".margin",
                      "expected less than half the width of \"" + b.name + "\" (" + num(width) + " m wide), got " +
                          num(edge) + " m: no spot on it is that far from both edges");
}

}  // namespace diverse
