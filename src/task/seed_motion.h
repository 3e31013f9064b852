// Finding a task's input motion M0 (paper section 7.1).
//
// Starts from a hand-authored small in-place jump and runs CMA-ES (optimize/cmaes.h) on
// the task's constraint penalty C, as the paper does for each jump. With continuation
// (Jump onto, Jump over), the scene object's height is raised in stages, each stage
// starting from the previous stage's best; intermediate stages stop as soon as C = 0.
//
// Objective: f = C - robustness * min(margin, 0.1 m), where margin is the smallest slack
// inside the allowed region (task/constraints.h, constraint_margin). Outside the region f
// is the penalty alone (margin < 0 is clipped to 0 there); inside it a small reward for
// slack prefers input motions that land near the middle of their box or clear their
// obstacle with room, so the diversity optimizer starts from a motion with margin.
// With robustness = 0 this is the penalty alone. A candidate that meets the task is
// simulated again with the timestep halved and counts as meeting it only if it does so
// there too (C is then the larger of the two), so input motions do not hinge on
// integration details.
//
// Deterministic for a given task seed: CMA-ES draws from seeds derived from it, and the
// generation's samples are evaluated in parallel into fixed slots.
#pragma once

#include <functional>
#include <string>

#include "control/parameters.h"
#include "task/task.h"

namespace diverse {

struct SeedOptions {
  int threads = 1;
  int generations = 0;  // per stage; 0 = the task's seed.generations
  // Called after every generation with a one-line progress report.
  std::function<void(const std::string&)> log;
};

struct SeedResult {
  ParameterSet parameters;
  double constraint = 0;  // C of the result on the full task
  double margin = 0;      // constraint_margin of the result (m)
  bool fell = true;
  long long evaluations = 0;
  double seconds = 0;
};

// `start` holds the starting parameters (names and values of the task's controller).
SeedResult seed_motion(const Task& task, const ParameterSet& start, const SeedOptions& options);

}  // namespace diverse
