#include "task/constraints.h"

#include <algorithm>
#include <cmath>

namespace diverse {
namespace {

// The peak COM height the task asks for (m above the floor).
double peak_height_required(const TaskConstraints& c, const MotionSummary& motion) {
  return c.peak_height_min + (c.peak_height_relative ? motion.standing_com_z : 0.0);
}

// The root's rotation between take-off and touch-down in the direction of the turns (rad).
double flight_turn(const TaskConstraints& c, const MotionSummary& motion) {
  return c.rotation_turns < 0 ? -motion.rotation_flight : motion.rotation_flight;
}

}  // namespace

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

double foot_slip_excess(const TaskConstraints& c, const MotionSummary& motion) {
  return c.foot_slip ? std::max(0.0, motion.foot_slip - c.max_foot_slip) : 0.0;
}

double foot_slip_margin(const TaskConstraints& c, const MotionSummary& motion) {
  if (!c.foot_slip || !(c.max_foot_slip > 0)) return INFINITY;
  return 0.1 * (1 - motion.foot_slip / c.max_foot_slip);
}

ConstraintReport evaluate_constraints(const Task& task, const MotionSummary& motion) {
  if (task.walk.enabled) return walk_constraints(task, motion);
  const TaskConstraints& c = task.constraints;
  ConstraintReport report;
  auto add = [&](const char* name, double violation, double penalty) {
    report.terms.push_back({name, violation, penalty});
    report.total += penalty;
  };
  auto quadratic = [&](const char* name, double d) { add(name, d, c.weight * d * d); };

  if (motion.unstable) {
    add("unstable", 1, 3 * c.fall_penalty);
    report.fell = true;
    return report;
  }
  const double progress = std::clamp(motion.fall_progress, 0.0, 1.0);
  add("fall", motion.fell ? 1 : 0, motion.fell ? c.fall_penalty * (2 - progress) : 0);
  report.fell = motion.fell;
  // A rollout ended once it could no longer meet the task counts as a fall at the end of
  // the motion: most such landings do fall later (85 of 105 around jump_high's M0), and a
  // C without it would rank them above every motion that stands longer before falling.
  if (motion.ended_decided) add("ended_decided", 1, c.fall_penalty);

  // The larger violation of the feet at touch-down and at rest.
  auto at_touchdown_and_rest = [&](auto violation) {
    return std::max(violation(motion.touchdown_feet_x, motion.touchdown_feet_z),
                    violation(motion.feet_x, motion.feet_z));
  };
  if (c.landing && c.landing_radius > 0) {
    const double touchdown = std::hypot(motion.touchdown_feet_x - c.landing_center,
                                        motion.touchdown_feet_y - c.landing_lateral);
    const double rest = std::hypot(motion.feet_x - c.landing_center, motion.feet_y - c.landing_lateral);
    quadratic("landing", std::max(0.0, std::max(touchdown, rest) - c.landing_radius));
  } else if (c.landing) {
    quadratic("landing", at_touchdown_and_rest([&](double x, double) {
                return std::max(0.0, std::fabs(x - c.landing_center) - c.landing_half_width);
              }));
  }
  if (c.on_box) {
    const SceneObject* box = task.find_object(c.on_box_object);
    const double lo = box->x_min + c.on_box_margin, hi = box->x_max - c.on_box_margin;
    quadratic("on_box", at_touchdown_and_rest([&](double x, double z) {
                const double dx = std::max({0.0, lo - x, x - hi});
                // The foot centre sits one foot radius above the surface it stands on.
                const double dz = std::max(0.0, box->height - z);
                return std::hypot(dx, dz);
              }));
  }
  if (c.clearance) {
    quadratic("clearance", std::max(0.0, c.min_clearance - motion.min_clearance));
  }
  if (c.min_length) {
    quadratic("min_length", at_touchdown_and_rest([&](double x, double) {
                return std::max(0.0, c.min_length_value - x);
              }));
  }
  if (c.peak_height) {
    quadratic("peak_height", std::max(0.0, peak_height_required(c, motion) - motion.peak_com_z));
  }
  if (c.rotation) {
    const double d = std::max(0.0, std::fabs(motion.rotation_total - 2 * M_PI * c.rotation_turns) -
                                       c.rotation_tolerance);
    add("rotation", d, d > 0 ? c.rotation_penalty + c.weight * d * d : 0);
    if (c.min_flight_rotation > 0) {
      // A motion that never landed has no rotation in the air; the fall term covers it.
      const double turned = motion.landed ? flight_turn(c, motion) : c.min_flight_rotation;
      quadratic("flight_rotation", motion.landed ? std::max(0.0, c.min_flight_rotation - turned) : 0.0);
    }
  }
  if (c.pitch) {
    quadratic("pitch", std::max(0.0, motion.max_forward_pitch - c.max_pitch));
  }
  if (c.foot_slip) quadratic("foot_slip", foot_slip_excess(c, motion));
  return report;
}

double peak_bound(const Task& task, const MotionSummary& motion) {
  const TaskConstraints& c = task.constraints;
  if (!c.peak_height) return 0;
  const double d = std::max(0.0, peak_height_required(c, motion) - motion.peak_com_z);
  return c.weight * d * d;
}

double touchdown_bound(const Task& task, const MotionSummary& motion) {
  MotionSummary at_touchdown = motion;
  at_touchdown.fell = false;
  at_touchdown.feet_x = motion.touchdown_feet_x;
  at_touchdown.feet_y = motion.touchdown_feet_y;
  at_touchdown.feet_z = motion.touchdown_feet_z;
  // The rotation from standing to standing is known only at rest.
  at_touchdown.rotation_total = 2 * M_PI * task.constraints.rotation_turns;
  return evaluate_constraints(task, at_touchdown).total;
}

double constraint_margin(const Task& task, const MotionSummary& motion) {
  if (task.walk.enabled) return walk_margin(task, motion);
  const TaskConstraints& c = task.constraints;
  double margin = 1.0;  // m; no constraint is looser than this counts
  if (c.landing && c.landing_radius > 0) {
    margin = std::min({margin,
                       c.landing_radius - std::hypot(motion.touchdown_feet_x - c.landing_center,
                                                     motion.touchdown_feet_y - c.landing_lateral),
                       c.landing_radius - std::hypot(motion.feet_x - c.landing_center,
                                                     motion.feet_y - c.landing_lateral)});
  }
  if (c.pitch) margin = std::min(margin, 0.2 * (c.max_pitch - motion.max_forward_pitch));
  for (const double x : {motion.touchdown_feet_x, motion.feet_x}) {
    if (c.landing && c.landing_radius <= 0)
      margin = std::min(margin, c.landing_half_width - std::fabs(x - c.landing_center));
    if (c.on_box) {
      const SceneObject* box = task.find_object(c.on_box_object);
      const double lo = box->x_min + c.on_box_margin, hi = box->x_max - c.on_box_margin;
      margin = std::min({margin, x - lo, hi - x});
    }
    if (c.min_length) margin = std::min(margin, x - c.min_length_value);
  }
  if (c.clearance) margin = std::min(margin, motion.min_clearance - c.min_clearance);
  margin = std::min(margin, foot_slip_margin(c, motion));
  if (c.peak_height) margin = std::min(margin, motion.peak_com_z - peak_height_required(c, motion));
  if (c.rotation) {
    const double miss = std::fabs(motion.rotation_total - 2 * M_PI * c.rotation_turns);
    margin = std::min(margin, 0.2 * (c.rotation_tolerance - miss));
    if (c.min_flight_rotation > 0)
      margin = std::min(margin, 0.2 * (flight_turn(c, motion) - c.min_flight_rotation));
  }
  return margin;
}

}  // namespace diverse
