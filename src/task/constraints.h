// Constraint penalty C(M) of a simulated jump (paper sections 3 and 7.1, SPEC 2.4).
//
// C is 0 inside the allowed region and K_c |d|^2 outside it, K_c = weight (5000) and d the
// amount of violation (m or rad). A fall costs a large constant: fall_penalty when the
// character falls after landing, rising linearly to 2 * fall_penalty for a fall at the
// very start (progress 0), so that an optimizer starting among falls still sees which
// candidates stay up longer (ours; the paper only says "a large constant penalty").
// Never leaving the ground, or never landing, counts as a fall. A rollout whose
// simulation blew up costs 3 * fall_penalty. Every constraint the task lists adds its own
// terms (task/term.h; each kind's file, task/term_<kind>.h, says which): the landing
// spot, a box's top, an obstacle's clearance, a length, the peak height, a rotation about
// pitch, roll or the vertical, the forward pitch, the foot slip.
//
// The half-timestep check (half_timestep): a motion that meets the task is simulated
// again with the timestep halved (TaskEvaluator, EvaluationOptions::half_timestep_check);
// the term "half_timestep" adds that rollout's C, plus K_c d^2 when the feet land (at
// touch-down or at rest) further than kTimestepAgreement + d from where they did at the
// task's timestep. A motion that exploits integration error does not meet the task.
//
// Where the character lands (the landing box, on_box, min_length) is checked twice: at
// the first touch-down after flight and at rest, and the larger violation counts. The
// jump itself has to cover the distance, and the feet have to stay where they came down:
// a motion that touches down short and hops or slides the rest of the way does not land
// in the box.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "task/task.h"
#include "task/term.h"
#include "task/walk_task.h"

namespace diverse {

// What a rollout measured, as the constraints need it.
struct MotionSummary {
  bool unstable = false;      // the simulation blew up
  bool took_off = false;      // became airborne during extend
  bool landed = false;        // touched down after flight
  bool settled = false;       // came to rest after landing + settle_time
  bool fell = false;          // fell, never took off, never landed, or never came to rest
  std::string fall_reason;    // empty unless fell
  double fall_progress = 1;   // how far the motion got before falling, in [0, 1]
  double peak_com_z = 0;      // m, highest whole-body COM during flight
  double standing_com_z = 0;  // m, the whole-body COM in the start pose, before anything moves
  double feet_x = 0, feet_y = 0, feet_z = 0;   // m, mean of the foot centres at the end
  double touchdown_feet_x = 0, touchdown_feet_y = 0, touchdown_feet_z = 0;  // m, the same at the first touch-down
  double rotation_total = 0;  // rad, root pitch at the end minus at the start
  double rotation_flight = 0; // rad, root pitch at landing minus at take-off
  // rad, a free root's turn between take-off and the first touch-down about the world's
  // forward axis x (roll, positive turning the left side up) and about the vertical
  // (positive turning left seen from above); 0 for a planar root (task/term_rotation.h).
  double roll_flight = 0, vertical_flight = 0;
  double min_clearance = 0;   // m, smallest body-obstacle distance (clearance_range if never near)
  double max_forward_pitch = 0;  // rad, the root's largest forward pitch from standing (3D)
  double end_time = 0;        // s
  // m, the largest slide of a planted foot in one stance (task/foot_slip.h), measured in
  // the rollout when the task bounds it (task/term_foot_slip.h); 0 otherwise.
  double foot_slip = 0;
  // The rollout was ended once the motion could no longer meet the task
  // (EvaluationOptions::end_when_decided). A jump (ended once landed): the feet "at rest"
  // are where they were then, the rotation from standing to standing, known only at rest,
  // counts as met, and the term "ended_decided" adds fall_penalty, a fall at the end of
  // the motion. A walk (ended at the step that broke the rules): the term extrapolates
  // its steps' excesses to all its evaluated steps (task/walk_task.h).
  bool ended_decided = false;
  WalkSummary walk;           // a walk task's steps (task/walk_task.h)
};

struct ConstraintTerm {
  std::string name;        // "fall", "landing", "on_box", "clearance", ...
  double violation = 0;    // d (m or rad), 0 when satisfied
  double penalty = 0;      // contribution to C
};

struct ConstraintReport {
  std::vector<ConstraintTerm> terms;
  double total = 0;  // C
  bool fell = false;
  void add(std::string name, double violation, double penalty) {
    terms.push_back({std::move(name), violation, penalty});
    total += penalty;
  }
};

// C: the fixed terms (a blown-up simulation, a fall, a rollout ended once decided), then
// every listed constraint's terms in the task's order (task/term.h); a walk task's own
// terms come from walk_constraints() (task/walk_task.h).
ConstraintReport evaluate_constraints(const Task& task, const MotionSummary& motion);

// Two simulations of one motion at different timesteps agree when the feet land within
// this distance (m) of the same spot, at touch-down and at rest.
constexpr double kTimestepAgreement = 0.03;

// The larger of the horizontal distances between a's and b's feet at touch-down and at
// rest (m).
double landing_shift(const MotionSummary& a, const MotionSummary& b);

// The half-timestep term for a motion that meets the task at its timestep (`coarse`),
// given the same motion simulated with the timestep halved (`fine`, its C `fine_c`):
// penalty fine_c + K_c d^2, d the landing shift beyond kTimestepAgreement (0 when either
// did not land); violation d, or 1 when the fine motion does not meet the task.
ConstraintTerm half_timestep_term(const Task& task, const MotionSummary& coarse,
                                  const MotionSummary& fine, double fine_c);

// When a jump's outcome is decided part-way through its rollout (TaskEvaluator:
// Evaluation::steps_after_decided), never for C itself. broken_at(): some constraint is
// broken for good by what the rollout has shown up to `moment` (the peak height once the
// peak is behind; the obstacle clearance or the forward pitch at any step). touchdown_bound():
// at the first touch-down, a lower bound on C from every term the rest of the motion can
// only make worse (the landing spot and rotation in the air, the obstacle clearance, the
// forward pitch, the peak), with the feet at rest taken to be where they touched down.
bool broken_at(const Task& task, const MotionSummary& motion, Moment moment);
double touchdown_bound(const Task& task, const MotionSummary& motion);

// How far inside the allowed region the motion is: the smallest slack (m) over the
// task's constraints (Constraint::margin(): landing box, box edges, clearance, length,
// peak height; rotation and pitch slack count 0.2 m per rad; a foot-slip bound 0.1 m
// times the share of it left unused), at most 1 m, negative when violated. Used only to prefer
// robust input motions when seeding (`diverse seed-motion`), never inside C.
double constraint_margin(const Task& task, const MotionSummary& motion);

}  // namespace diverse
