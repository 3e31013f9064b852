// Clearance of an obstacle (kind "clearance"): the character's smallest distance to a
// scene object of kind "obstacle" stays at least `min_clearance`.
//
//   object = "bar", min_clearance = 0.02    # m
//
// The obstacle reports near-contacts up to simulation.clearance_range (its MJCF margin,
// task.h scene_xml()), so the rollout sees how close any body came; C adds K_c d^2, d the
// shortfall (m). A distance only shrinks: once short, the motion cannot meet it.
#pragma once

#include <string>

#include "task/term.h"

namespace diverse {

class ClearanceConstraint : public Constraint {
 public:
  using Constraint::Constraint;
  const char* kind() const override { return "clearance"; }
  void penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const override;
  double margin(const Task& task, const MotionSummary& motion) const override;
  bool broken(const Task& task, const MotionSummary& so_far, Moment moment) const override;
  // MotionSummary::min_clearance: the smallest distance of a contact with the object.
  std::unique_ptr<TermObserver> observer(const mjModel* m, const Character& body) const override;
  // min_clearance is below the distance up to which proximity is seen.
  void check(const Task& task) const override;

  std::string object;         // a scene object of kind "obstacle"
  double min_clearance = 0;   // m
  double weight = 5000;       // K_c
};

void read_clearance(const TomlReader& r, const Task& task, TaskConstraints& c);

}  // namespace diverse
