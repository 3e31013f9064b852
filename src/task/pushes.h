// Where and which way a push falls (EvaluationOptions::push, task/evaluate.h): the ground
// phases of a rollout and the directions of a round of pushes. The robustness suite
// (robust/robustness.h) draws its pushes with them, and so does the input-motion search's
// push term (task/seed_motion.h, SeedOptions::pushes).
//
//   const GroundWindows w = ground_windows(task, evaluation);
//   options.push.time = w[0].begin + u * (w[0].end - w[0].begin);   // u in [0, 1)
//   const PushDirection& d = push_direction(k, planar);             // k-th of a round
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

}  // namespace diverse
