// Where and which way a push falls (EvaluationOptions::push, task/evaluate.h): the ground
// phases of a rollout and the directions of a round of pushes. The robustness suite
// (robust/robustness.h) draws its pushes with them, and so does the input-motion search's
// push term (task/seed_motion.h, SeedOptions::pushes).
//
//   const GroundWindows w = ground_windows(task, evaluation);
//   options.push = draw_push(w, k, planar, 0, u, 0.3).push;   // push k, u in [0, 1)
//
// Ground phases.
// A jump: [0] from the start to take-off ("takeoff"), [1] from touch-down to touch-down
// plus the task's settle_time, or the rollout's end if sooner ("landing"). A walk: both
// are its evaluated steps, from the touch-down of its last settling step to its last
// touch-down ("steps"). A rollout without the phase (it never took off, never landed,
// fell before its evaluated steps) gives [0, its end) ("motion").
#pragma once

#include <array>

#include "task/evaluate.h"
#include "task/task.h"

namespace diverse {

struct GroundWindow {
  double begin = 0, end = 0;  // s
  const char* phase = "motion";
};
using GroundWindows = std::array<GroundWindow, 2>;

GroundWindows ground_windows(const Task& task, const Evaluation& e);

// Directions, in turn: forward (+x, where every character faces at the start), backward,
// and for a 3D root left (+y) and right; a planar root is pushed forward and backward
// only, in its plane. A round is push_directions(planar) pushes.
struct PushDirection {
  const char* name;
  std::array<double, 3> axis;
};
int push_directions(bool planar);                          // 2 or 4
const PushDirection& push_direction(int k, bool planar);   // k modulo a round

// Push k of a series: its direction by k in turn, its ground phase alternating after
// every round of directions (window (k / round + first_window) % 2), its moment at
// `fraction` (in [0, 1)) of that phase, and `speed` (m/s) along the direction.
struct PushDraw {
  EvaluationOptions::Push push;
  const char* phase;      // the window's name
  const char* direction;  // the direction's name
};
PushDraw draw_push(const GroundWindows& windows, int k, bool planar, int first_window, double fraction,
                   double speed);

}  // namespace diverse
