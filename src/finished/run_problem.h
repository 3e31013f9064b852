// Simulating more points of a finished run: the run's task, distance and parameter layout
// rebuilt from run.json, so that points the run did not return (the optimization paths
// of `diverse gallery`, the blends of `diverse blend`) are simulated exactly as the run
// simulated its samples, each on its own body when the run varied the shape.
//
// A run's parameter vector is the controller's named parameters and, for a run whose
// shape varied ("vary": ["control", "shape"]), the shape scales after them
// (eval/motion_problem.h); normalized, every coordinate lies in [0, 1].
#pragma once

#include <Eigen/Dense>

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/motion_problem.h"
#include "finished/run_view.h"
#include "params/parameters.h"
#include "task/evaluate.h"

namespace diverse {

struct RunProblem {
  std::unique_ptr<const TaskEvaluator> evaluator;  // the run's task file
  std::unique_ptr<const MotionProblem> problem;    // the run's distance, M0 as reference
  bool vary_shape = false;
  ParameterSet like;                               // names and ranges of a parameter vector
  std::vector<Eigen::VectorXd> motions;            // normalized parameters of M0..MN
};

// Rebuilds the run's problem with `threads` workers (0 = one per core). Throws UserError
// naming run.json's task_file if it is missing or changed since the run (the text in
// run.json is what the run simulated); `consequence` ends that line (what cannot be done
// and how to go on), and on malformed motion files.
RunProblem open_run_problem(const RunView& run, int threads, const std::string& consequence);

// Named parameters (and shape scales) from a path or motion file, as `like` names them;
// strict (ParameterSet::set_from_json), except that a value off its bound by a rounding
// error (a normalized coordinate of exactly 0 or 1 written as named) is put back on it.
ParameterSet named_parameters(const ParameterSet& like, nlohmann::json values, const std::string& origin);
// A motion file's "parameters".
ParameterSet motion_parameters(const ParameterSet& like, const std::filesystem::path& motion_file);

// One point of a variation's optimization path (paths/m<i>.json), or its result.
struct RunPathPoint {
  Eigen::VectorXd x;      // normalized parameters
  long long generation = -1;
  long long step = -1;
  bool result = false;    // the variation's result (motions/m<i>.json), the path's last point
};
// Variation v's path: where it stood after each of its steps, then its result. Throws
// UserError if the path file is missing or malformed.
std::vector<RunPathPoint> read_run_path(const RunView& run, std::size_t variation, const ParameterSet& like);

// A fingerprint of the run's result (summary.json without its "timing" object, FNV-1a,
// 16 hex digits): what its blends were made from, so a gallery can tell blends of a run
// that was since replaced.
std::string run_fingerprint(const RunView& run);

}  // namespace diverse
