#include "task/walk_task.h"

#include <algorithm>
#include <cmath>

#include "core/toml_reader.h"
#include "task/constraints.h"
#include "task/task.h"

namespace diverse {
namespace {

constexpr double kDeg = M_PI / 180;

void read_range(const TomlReader& r, const char* key, double lo, double hi, double& center,
                double& half_width) {
  const toml::table* t = r.table(key, false);
  if (t == nullptr) return;
  TomlReader s = r.sub(key, *t);
  s.only({"center", "half_width"});
  center = s.number("center", lo, hi);
  half_width = s.number("half_width", 0, hi - lo);
}

}  // namespace

void read_walk(const TomlReader& r, TaskWalk& w) {
  r.only({"steps", "settle_steps", "forward", "lateral", "max_tilt", "max_turn", "max_flight", "max_time", "step_from"});
  w.enabled = true;
  w.steps = static_cast<int>(r.integer("steps", 1, 1000, w.steps));
  w.settle_steps = static_cast<int>(r.integer("settle_steps", 0, w.steps - 1, std::min(w.settle_steps, w.steps - 1)));
  read_range(r, "forward", -5, 5, w.forward_center, w.forward_half_width);
  read_range(r, "lateral", -5, 5, w.lateral_center, w.lateral_half_width);
  w.max_tilt_deg = r.number("max_tilt", 0, 90, w.max_tilt_deg);
  w.max_turn_deg = r.number("max_turn", 0, 360, w.max_turn_deg);
  w.max_flight = r.number("max_flight", 0, 10, w.max_flight);
  w.max_time = r.number("max_time", 1, 600, w.max_time);
  if (r.has("step_from")) {
    const std::string from = r.string("step_from");
    if (from != "foot" && from != "footprint") {
      r.fail("step_from", "expected \"foot\" (the other foot where it is) or \"footprint\" (where it last touched down), got \"" + from + "\"");
    }
    w.from_footprint = from == "footprint";
  }
}

double largest_turn(const WalkSummary& walk) {
  double turn = 0;
  for (const WalkStep& s : walk.steps) turn = std::max(turn, std::fabs(s.heading - walk.start_heading));
  return turn;
}

ConstraintReport walk_constraints(const Task& task, const MotionSummary& motion) {
  const TaskConstraints& c = task.constraints;
  const TaskWalk& w = task.walk;
  ConstraintReport report;
  auto add = [&](const char* name, double violation, double penalty) {
    report.terms.push_back({name, violation, penalty});
    report.total += penalty;
  };
  if (motion.unstable) {
    add("unstable", 1, 3 * c.fall_penalty);
    report.fell = true;
    return report;
  }
  const std::vector<WalkStep>& steps = motion.walk.steps;
  const double taken = std::min(static_cast<double>(steps.size()), static_cast<double>(w.steps));
  add("fall", motion.fell ? 1 : 0, motion.fell ? c.fall_penalty * (1 - taken / w.steps) : 0);
  report.fell = motion.fell;
  // Sums of squared excesses over the evaluated steps.
  double forward = 0, lateral = 0, tilt = 0;
  for (size_t i = static_cast<size_t>(w.settle_steps); i < steps.size(); ++i) {
    const WalkStep& s = steps[i];
    const double f = std::max(0.0, std::fabs(s.forward - w.forward_center) - w.forward_half_width);
    const double l = std::max(0.0, std::fabs(s.lateral - w.lateral_center) - w.lateral_half_width);
    const double t = std::max(0.0, s.tilt - w.max_tilt_deg * kDeg);
    forward += f * f;
    lateral += l * l;
    tilt += t * t;
  }
  const double turn = std::max(0.0, largest_turn(motion.walk) - w.max_turn_deg * kDeg);
  add("step_forward", std::sqrt(forward), c.weight * forward);
  add("step_lateral", std::sqrt(lateral), c.weight * lateral);
  add("upright", std::sqrt(tilt), c.weight * tilt);
  add("turn", turn, c.weight * turn * turn);
  // The constraints the task lists (a walk's: the foot slip).
  for (const auto& term : c.terms) term->penalize(task, motion, report);
  // A walk ended at the step that first broke the rules (MotionSummary::ended_decided):
  // its evaluated steps so far stand for all of them, as a walk that has settled into its
  // gait repeats its steps, so their excesses count (evaluated steps) / (steps so far)
  // times.
  if (motion.ended_decided) {
    const double evaluated = static_cast<double>(w.steps - w.settle_steps);
    const double so_far = std::max(1.0, static_cast<double>(steps.size()) - w.settle_steps);
    add("ended_decided", evaluated / so_far, (evaluated / so_far - 1) * c.weight * (forward + lateral + tilt));
  }
  return report;
}

double walk_margin(const Task& task, const MotionSummary& motion) {
  const TaskWalk& w = task.walk;
  const std::vector<WalkStep>& steps = motion.walk.steps;
  if (motion.fell || motion.unstable || steps.size() < static_cast<size_t>(w.steps)) return -1;
  double margin = INFINITY;
  for (size_t i = static_cast<size_t>(w.settle_steps); i < steps.size(); ++i) {
    const WalkStep& s = steps[i];
    margin = std::min({margin, w.forward_half_width - std::fabs(s.forward - w.forward_center),
                       w.lateral_half_width - std::fabs(s.lateral - w.lateral_center),
                       w.max_tilt_deg * kDeg - s.tilt});
  }
  margin = std::min(margin, w.max_turn_deg * kDeg - largest_turn(motion.walk));
  for (const auto& term : task.constraints.terms) margin = std::min(margin, term->margin(task, motion));
  return std::isfinite(margin) ? margin : -1;
}

}  // namespace diverse
