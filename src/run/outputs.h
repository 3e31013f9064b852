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

// The film strip's columns for one motion: qpos at the phase events of a jump
// (crouch, extend, take-off, half-way up, peak, half-way down, touch-down, end).
struct FilmColumns {
  std::vector<std::string> names;
  std::vector<std::vector<double>> frames;
};
FilmColumns jump_film_columns(const Evaluation& evaluation, const StepRecorder& record);

}  // namespace diverse
