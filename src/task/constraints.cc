#include "task/constraints.h"

#include <algorithm>
#include <cmath>

namespace diverse {

double landing_shift(const MotionSummary& a, const MotionSummary& b) {
  return std::max(std::hypot(a.touchdown_feet_x - b.touchdown_feet_x, a.touchdown_feet_y - b.touchdown_feet_y),
                  std::hypot(a.feet_x - b.feet_x, a.feet_y - b.feet_y));
}

ConstraintTerm half_timestep_term(const Task& task, const MotionSummary& coarse,
                                  const MotionSummary& fine, double fine_c) {
  const bool both_landed = coarse.landed && fine.landed && !coarse.fell && !fine.fell &&
                           !coarse.unstable && !fine.unstable;
  const double d = both_landed ? std::max(0.0, landing_shift(coarse, fine) - kTimestepAgreement) : 0.0;
  ConstraintTerm term;
  term.name = "half_timestep";
  term.penalty = fine_c + task.constraints.weight * d * d;
  term.violation = fine_c > 0 ? std::max(1.0, d) : d;
  return term;
}

ConstraintReport evaluate_constraints(const Task& task, const MotionSummary& motion) {
  if (task.walk.enabled) return walk_constraints(task, motion);
  const TaskConstraints& c = task.constraints;
  ConstraintReport report;
  if (motion.unstable) {
    report.add("unstable", 1, 3 * c.fall_penalty);
    report.fell = true;
    return report;
  }
  const double progress = std::clamp(motion.fall_progress, 0.0, 1.0);
  report.add("fall", motion.fell ? 1 : 0, motion.fell ? c.fall_penalty * (2 - progress) : 0);
  report.fell = motion.fell;
  // A rollout ended once it could no longer meet the task counts as a fall at the end of
  // the motion: most such landings do fall later (85 of 105 around jump_high's M0), and a
  // C without it would rank them above every motion that stands longer before falling.
  if (motion.ended_decided) report.add("ended_decided", 1, c.fall_penalty);

  for (const auto& term : c.terms) term->penalize(task, motion, report);
  return report;
}

bool broken_at(const Task& task, const MotionSummary& motion, Moment moment) {
  for (const auto& term : task.constraints.terms)
    if (term->broken(task, motion, moment)) return true;
  return false;
}

double touchdown_bound(const Task& task, const MotionSummary& motion) {
  MotionSummary at_touchdown = motion;
  at_touchdown.fell = false;
  at_touchdown.feet_x = motion.touchdown_feet_x;
  at_touchdown.feet_y = motion.touchdown_feet_y;
  at_touchdown.feet_z = motion.touchdown_feet_z;
  // What is known only at rest (the rotation from standing to standing) counts as met.
  for (const auto& term : task.constraints.terms) term->assume_met_at_rest(at_touchdown);
  return evaluate_constraints(task, at_touchdown).total;
}

double constraint_margin(const Task& task, const MotionSummary& motion) {
  if (task.walk.enabled) return walk_margin(task, motion);
  double margin = 1.0;  // m; no constraint is looser than this counts
  for (const auto& term : task.constraints.terms) margin = std::min(margin, term->margin(task, motion));
  return margin;
}

}  // namespace diverse
