// On a box (kind "on_box"): the feet land on top of a scene object of kind "box", at
// least `margin` from its edges.
//
//   object = "box", margin = 0.1         # m
//
// Judged at the first touch-down and at rest, as the landing constraint is; d (m) is
// the distance of the feet from the allowed strip on the box's top (a foot centre sits
// one foot radius above the surface it stands on, so below the top counts by how far).
#pragma once

#include <string>

#include "task/term.h"

namespace diverse {

struct SceneObject;

class OnBoxConstraint : public Constraint {
 public:
  using Constraint::Constraint;
  const char* kind() const override { return "on_box"; }
  void penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const override;
  double margin(const Task& task, const MotionSummary& motion) const override;
  std::optional<std::pair<double, double>> feet_x_range(const Task& task) const override;
  // The margin leaves some of the box's top.
  void check(const Task& task) const override;

  std::string object;    // a scene object of kind "box"
  double edge = 0.1;     // m, the `margin` from the box's edges
  double weight = 5000;  // K_c

 private:
  const SceneObject& box(const Task& task) const;
};

void read_on_box(const TomlReader& r, const Task& task, TaskConstraints& c);

// Fails `key` of `r` unless `name` is a scene object of `kind`.
void require_object(const TomlReader& r, const Task& task, const char* key, const std::string& name,
                    const char* kind);

}  // namespace diverse
