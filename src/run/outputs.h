// What a finished (or resumed-and-finished) run writes: summary.json, log.jsonl,
// paths/, motions/ with their saved models, and the film strip. See run/run.h.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/thread_pool.h"
#include "eval/motion_problem.h"
#include "optimize/diversity.h"
#include "physics/rollout.h"
#include "task/evaluate.h"

namespace diverse {

struct RunOutputs {
  std::filesystem::path dir;
  const TaskEvaluator& evaluator;
  const MotionProblem& problem;  // names the parameters (MotionProblem::named)
  const DiversityOptimizer& optimizer;
  ThreadPool& pool;
  double wall_seconds = 0;  // total, over all sessions of the run
  bool render = true;
  int ranks = 1;            // processes that evaluated (mpirun -n; distribute/cluster.h)
  nlohmann::json messages = nullptr;  // ranks > 1: what went between them ("timing" "messages")
  nlohmann::json rollouts = nullptr;  // one process: its rollouts' CPU times ("timing" "rollouts")
  nlohmann::json custom = nullptr;    // a program's own distance or constraint term (RunHooks)
};

// summary.json: the run's settings and result ("metric" the objective's distance, "vary"
// the parameter groups, "strength", "bounds"; "samples" the optimizer's samples and
// "feasible_samples" how many of them met their constraints; "confirmations" the
// half-timestep checks the optimizer ran, "steps" the simulation steps by kind and outcome,
// eval/motion_problem.h, steps_of(); "robustness" each motion's shares of the robustness
// suite, by kind and over all, whose every rollout is in robustness.json,
// robust/robustness.h), per motion its C (the
// task's constraints and the bounds'; "task_constraint" the task's alone), dmin, effort
// (N^2 m^2 s), "effort_ratio" to M0's, "positive_work" (J), "distance_to_m0" in the
// objective's distance, "within_bounds", "foot_slip" (how far its planted feet slide, per
// side, measured by replaying its motion file: task/foot_slip.h), shape scales and link lengths (m,
// "link_names" order; none for a character without shape parameters), and "distances": the pairwise matrices over M0..MN of every motion
// metric (hf, md, wja) and of the shape metric (all zero when the shape did not vary),
// plus the objective's own matrix when it combines a motion metric with the shape.
void write_run_outputs(const RunOutputs& outputs);

}  // namespace diverse
