// Walk tasks: what a walk must achieve, what a walk rollout measured, and its constraint
// penalty (the walk counterpart of task/constraints.h).
//
// A task is a walk when its file has a [walk] table (and its controller is a walk
// controller, ControllerType::skill() == "walk"):
//
//   [walk]
//   steps = 30                  # steps simulated; the rollout ends at the last touch-down
//   settle_steps = 10           # the first steps let the walk settle; the rest are evaluated
//   forward = { center = 1.0, half_width = 0.5 }   # m, every evaluated step
//   lateral = { center = 0.0, half_width = 0.5 }   # m, every evaluated step
//   max_tilt = 15.0             # degrees from vertical, pelvis and torso, evaluated steps
//   max_turn = 30.0             # degrees, heading change from the start, every touch-down
//   max_flight = 0.05           # s, longest time both feet may be off the ground at once
//   max_time = 40.0             # s; a walk that has not taken `steps` steps by then fell
//   step_from = "foot"          # or "footprint": where a step is measured from (below)
//
// A step is a foot landing after at least kMinAirTime (0.05 s) in the air, the feet
// alternating: a foot that lands again before the other one has is re-landing (counted,
// not a step). A foot is down while one of its geoms touches something that is not the
// character. Steps are found from these contacts, by the rule the walk audit uses
// (task/walk_audit.h), not from the controller's states: a swing foot set down beside
// the other one in the middle of its swing and lifted again is a step where it was set
// down. A step's length is where the landing foot is (its body origin: the human's ankle,
// the robot's toe joint) minus where the other foot is at that moment, in the heading
// frame at the touch-down: forward along the root's forward axis turned onto the ground,
// lateral to its left. (Measured from where the other foot landed instead, a foot that
// slid or shuffled back after landing let backward steps count as long ones.) With
// step_from = "footprint" a step is measured from the other foot's body origin at its
// last touch-down instead (its start position before its first), footprint to
// footprint, which a foot-slip bound keeps honest. The rollout
// ends when the walk has taken `steps` steps and the controller has ended as many strike
// states (for a walk whose feet land only when its swings end, the same touch-down).
//
// Drift and turns. Step lengths are measured in the walker's own heading frame, so a
// walk that curves gently is judged by its steps, not by where it heads; a walk that
// sidles steps sideways, which the lateral range catches. At every touch-down of the walk,
// the settling steps included, the heading must be within max_turn degrees of the
// heading at the start; beyond that the walk is turning, not walking (a walk that turns
// round in its first steps and then goes straight is another task), and pays K_c d^2
// with d the largest excess in rad.
//
// C for a walk: K_c |d|^2 over every evaluated step's forward and lateral excess (m),
// every pelvis/torso tilt excess (rad, the largest over each evaluated step) and the
// turn excess (rad); a fall (a body other than the feet touching anything, the COM
// within fall_com_height of the feet, a strike state that ends without a touch-down, both
// feet off the ground for longer than max_flight (a hop: a walk has no flight phase), not
// reaching `steps` steps within max_time) costs fall_penalty * (1 - k / steps) with k the
// steps taken before it: fall_penalty for a fall in the first step, falling linearly to 0
// after the last. A rollout whose simulation blew up costs 3 * fall_penalty.
#pragma once

#include <string>
#include <vector>

namespace diverse {

class TomlReader;
struct Task;
struct MotionSummary;
struct ConstraintReport;

struct TaskWalk {
  bool enabled = false;  // the task file has a [walk] table
  int steps = 30;
  int settle_steps = 10;
  double forward_center = 1.0, forward_half_width = 0.5;  // m
  double lateral_center = 0.0, lateral_half_width = 0.5;  // m
  double max_tilt_deg = 15;
  double max_turn_deg = 30;
  double max_flight = 0.05;  // s, both feet off the ground at once
  double max_time = 40;  // s
  // Where a step is measured from: the other foot where it is at the touch-down ("foot",
  // the default), or where it last touched down ("footprint": footprint to footprint, as
  // a person measures a walk's steps; with a foot-slip bound, [constraints] foot_slip, a
  // foot cannot shuffle back after landing to lengthen the next step).
  bool from_footprint = false;
};

// Parses a [walk] table into `walk` (enabled). Throws UserError "FILE: walk.KEY: expected ...".
void read_walk(const TomlReader& r, TaskWalk& walk);

// One step of a walk.
struct WalkStep {
  int leg = 0;            // the leg that touched down: 0 left, 1 right
  double time = 0;        // s
  double forward = 0;     // m, heading frame at the touch-down
  double lateral = 0;     // m
  double heading = 0;     // rad, at the touch-down (unwrapped over the walk)
  double tilt = 0;        // rad, the largest pelvis or torso tilt since the previous step
};

struct WalkSummary {
  std::vector<WalkStep> steps;  // at most the task's `steps`
  int relandings = 0;           // landings of the foot that had made the previous step
  double start_heading = 0;  // rad
};

// The largest |heading - start heading| over the walk's touch-downs (rad).
double largest_turn(const WalkSummary& walk);

// The walk terms of C (called by evaluate_constraints() for a walk task).
ConstraintReport walk_constraints(const Task& task, const MotionSummary& motion);
// The smallest slack (m; tilt and turn count 1 m per rad) over the evaluated steps'
// ranges, negative when violated; -1 for a fall (called by constraint_margin()).
double walk_margin(const Task& task, const MotionSummary& motion);

}  // namespace diverse
