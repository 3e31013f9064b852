#include "task/term_rotation.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/toml_reader.h"
#include "task/constraints.h"
#include "task/task.h"

namespace diverse {

const RotationConstraint* find_rotation(const TaskConstraints& c, RotationAxis axis) {
  for (const auto& term : c.terms) {
    const auto* r = dynamic_cast<const RotationConstraint*>(term.get());
    if (r != nullptr && r->axis == axis) return r;
  }
  return nullptr;
}

void read_rotation(const TomlReader& r, const Task& task, TaskConstraints& c) {
  r.only({"axis", "turns", "tolerance", "penalty", "min_flight", "weight"});
  auto t = std::make_shared<RotationConstraint>(r.path());
  const std::string axis = r.string("axis", "pitch");
  if (axis == "pitch") {
    t->axis = RotationAxis::kPitch;
  } else if (axis == "roll") {
    t->axis = RotationAxis::kRoll;
  } else if (axis == "vertical") {
    t->axis = RotationAxis::kVertical;
  } else {
    r.fail("axis", "expected \"pitch\", \"roll\" or \"vertical\", got \"" + axis + "\"");
  }
  if (t->axis != RotationAxis::kPitch && task.character_spec->root == RootKind::kPlanar)
    r.fail("axis", "expected \"pitch\": the planar character \"" + task.character_spec->name +
                       "\" turns only about its lateral axis, got \"" + axis + "\"");
  if (find_rotation(c, t->axis) != nullptr)
    r.fail("axis", "expected one rotation constraint per axis, \"" + axis + "\" repeats");
  t->turns = r.number("turns", -3, 3);
  t->tolerance = r.number("tolerance", 0.01, 3.14);
  t->penalty = r.number("penalty", 0, 1e12);
  if (t->axis == RotationAxis::kPitch) {
    const double most = 2 * M_PI * std::fabs(t->turns) + t->tolerance;
    t->min_flight = r.number("min_flight", 0, 20, 0.0);
    if (t->min_flight > most) {
      std::ostringstream what;
      what << "expected a rotation in the air (rad) no larger than the whole turn allows, 2 pi |turns| + tolerance = "
           << most << ", got " << t->min_flight;
      r.fail("min_flight", what.str());
    }
  } else if (r.has("min_flight")) {
    r.fail("min_flight", "expected min_flight only with axis = \"pitch\" (a roll or vertical turn is measured in the air)");
  }
  t->weight = term_weight(r, c);
  c.terms.push_back(std::move(t));
}

double RotationConstraint::turned(const MotionSummary& motion) const {
  switch (axis) {
    case RotationAxis::kPitch: return motion.rotation_total;
    case RotationAxis::kRoll: return motion.landed ? motion.roll_flight : 0.0;
    case RotationAxis::kVertical: return motion.landed ? motion.vertical_flight : 0.0;
  }
  return 0;
}

void RotationConstraint::penalize(const Task& task, const MotionSummary& motion, ConstraintReport& report) const {
  (void)task;
  const char* name = axis == RotationAxis::kPitch ? "rotation"
                     : axis == RotationAxis::kRoll ? "rotation_roll"
                                                   : "rotation_vertical";
  // A roll or vertical turn is judged in the air: a motion that never landed has none,
  // and the fall term covers it.
  const double d = axis != RotationAxis::kPitch && !motion.landed
                       ? 0.0
                       : std::max(0.0, std::fabs(turned(motion) - 2 * M_PI * turns) - tolerance);
  report.add(name, d, d > 0 ? penalty + weight * d * d : 0);
  if (min_flight > 0) {
    // The root's rotation between take-off and touch-down in the direction of the turns.
    const double flight = turns < 0 ? -motion.rotation_flight : motion.rotation_flight;
    const double short_by = motion.landed ? std::max(0.0, min_flight - flight) : 0.0;
    report.add("flight_rotation", short_by, weight * short_by * short_by);
  }
}

double RotationConstraint::margin(const Task& task, const MotionSummary& motion) const {
  (void)task;
  double margin = 0.2 * (tolerance - std::fabs(turned(motion) - 2 * M_PI * turns));
  if (min_flight > 0) {
    const double flight = turns < 0 ? -motion.rotation_flight : motion.rotation_flight;
    margin = std::min(margin, 0.2 * (flight - min_flight));
  }
  return margin;
}

void RotationConstraint::assume_met_at_rest(MotionSummary& s) const {
  if (axis == RotationAxis::kPitch) s.rotation_total = 2 * M_PI * turns;
}

}  // namespace diverse
