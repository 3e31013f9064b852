// An audit of a recorded walk that does not trust the controller that made it.
//
//   WalkAudit a = audit_walk(model, record, character, task.walk);
//   if (!a.violations.empty()) ...   // one line per broken rule
//
// It goes through the motion's recorded qpos (which `diverse replay` checks against a
// plain-MuJoCo replay of the recorded inputs) on the motion's saved model and finds
// everything from geometry alone: a foot is down while one of its geoms touches a geom
// that is not the character's; a step is a foot landing after at least kMinAirTime in the
// air, alternating feet (a foot that lands twice in a row is a stumble, not a step, and is
// counted in `relandings`). A step's length is where the landing foot's body origin is,
// minus where the other foot's is at that moment (or, for a task that measures steps
// from footprints, TaskWalk::from_footprint, where it last touched down), in the heading
// frame of the root at the landing (its forward axis turned onto the ground, lateral to
// its left); the step from footprint to footprint is reported beside it
// (Step::footprint_forward). Tilt is the
// angle of the root's and the torso's standing "up" from world vertical (the torso: the
// body of the deepest centre waist hinge), the largest since the previous step. A fall is any contact of a non-foot geom of the character with
// something that is not the character; a walk never has both feet off the ground for
// longer than max_flight.
//
// Over the evaluated steps (settle_steps + 1 .. steps) the walk must take its steps with
// forward and lateral lengths in range and tilt within max_tilt; at every touch-down the
// heading must be within max_turn of the start's (task/walk_task.h): the task's rules,
// found independently.
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "character/character.h"
#include "physics/rollout.h"
#include "task/walk_task.h"

namespace diverse {

struct WalkAudit {
  struct Step {
    int leg = 0;          // 0 left, 1 right
    int sim_step = 0;     // index into the record
    double time = 0;      // s
    double forward = 0, lateral = 0;  // m, by the task's rule
    // m: footprint to footprint, as a person measures a step: where the landing foot's
    // body origin is, minus where the other foot's was when it last touched down (its
    // footprint), in the same heading frame. Differs from forward/lateral by how far the
    // other foot slid or rolled while it was down (task/foot_slip.h).
    double footprint_forward = 0, footprint_lateral = 0;
    double heading = 0;   // rad, unwrapped, relative to standing
    double tilt = 0;      // rad, largest pelvis/torso tilt since the previous step
  };
  std::vector<Step> steps;
  int relandings = 0;           // landings of the foot that had made the previous step
  double longest_flight = 0;    // s, both feet off the ground at once
  double flight_time = -1;      // s, when the longest flight began
  bool fell = false;            // a non-foot geom touched something outside the character
  double fall_time = -1;        // s, first such contact
  std::string fall_body;        // the body that touched
  double turn = 0;              // rad, largest |heading - start heading| at a touch-down
  double max_tilt = 0;          // rad, over the evaluated steps
  double forward_min = 0, forward_max = 0, lateral_min = 0, lateral_max = 0;  // evaluated
  double footprint_forward_min = 0, footprint_forward_max = 0;                 // evaluated
  std::vector<std::string> violations;  // empty: the walk meets the rules
};

// Landings closer than this after a foot left the ground are contact chatter (s).
inline constexpr double kMinAirTime = 0.05;

// The body a walk keeps upright besides the root: the child of the deepest centre waist
// hinge, or -1 if the character has none. The task's observer (task/walk_eval.h) and the
// audit use the same one.
int walk_torso(const Character& body);

// `m` is the motion's saved model (not modified), `record` its replay record, `body` the
// character bound to `m`.
WalkAudit audit_walk(const mjModel* m, const StepRecorder& record, const Character& body, const TaskWalk& walk);

}  // namespace diverse
