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
  const MotionProblem& problem;
  const ParameterSet& m0;  // names and ranges of the parameters
  const DiversityOptimizer& optimizer;
  ThreadPool& pool;
  double wall_seconds = 0;  // total, over all sessions of the run
  bool render = true;
};

void write_run_outputs(const RunOutputs& outputs);


}  // namespace diverse
