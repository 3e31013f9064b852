// A diversity run of a task, on disk (SPEC section 7).
//
// `diverse run TASK --out DIR` and `diverse resume DIR` both end here. A run directory:
//
//   run.json            settings: task file (absolute path and its text), metric (and the
//                       shape weight of a combined one), the parameter groups that vary
//                       ("vary": ["control"] or ["control", "shape"]), the optimizer's
//                       options, the character's strength ("strength", 1 when absent),
//                       the bounds on the variations ("bounds": {"effort": R,
//                       "distance": X, "robust": true}, eval/motion_problem.h), version
//   checkpoint.json     the optimizer's complete state at a generation boundary, written
//                       atomically (temp + rename) every few seconds and at the end
//   log.jsonl           one JSON record per CMA step (generation, variation, D, C, dmin,
//                       evaluations, half-timestep checks and simulation steps so far)
//   paths/m<i>.json     variation i's optimization path: where it stood after each of its
//                       steps, as named controller parameters (and shape scales)
//   summary.json        the result (run/outputs.h), written when the run ends
//   motions/m<i>.json   i = 0..N: parameters, phase boundaries, pose samples and the
//                       exact-replay record; model/m<i>.xml is the model it replays on
//                       (with varying shape, each motion's own body: the exact shaped
//                       MJCF text)
//   robustness.json     the robustness suite on M0..MN (robust/robustness.h), written
//                       when the run ends; summary.json has each motion's shares
//   filmstrip.png       M0..MN at the same phase events, one row each
//
// Under `mpirun -n R` rank 0 does all of the above and the other ranks only evaluate
// samples (distribute/cluster.h); the files are the same as a single process writes.
//
// Results never depend on the thread count, the number of ranks or on interruptions: a run killed at any
// moment and resumed from its checkpoint ends with the same summary.json as an
// uninterrupted one, except for the "timing" object (wall time, threads, ranks; under
// mpirun "messages", the traffic between the ranks; in one process "rollouts", the CPU
// time of every rollout this process ran, as deciles, and the sizes of the batches the
// strategy asked for: what scripts/scaling-model.py reads).
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "eval/motion_problem.h"
#include "optimize/diversity.h"

namespace diverse {

class Cluster;  // distribute/cluster.h

// What a program that embeds the library adds to a run (the Python module, python/):
struct RunHooks {
  // Called after every generation; returning false stops the run there: its checkpoint
  // is written (no summary), and resuming continues it as after an interruption.
  std::function<bool(const DiversityOptimizer&)> on_generation;
  // The problem the optimizer runs on in place of the task's own: a distance or a
  // constraint term of the caller's over the task's problem. Its outcomes must be the
  // task problem's MotionOutcomes (run/outputs.h reads them), and it must be pure like
  // any DiversityProblem. Not with a cluster.
  std::function<std::unique_ptr<DiversityProblem>(const MotionProblem&)> wrap_problem;
  // What wrap_problem changes, e.g. {"metric": "my_metric"}: written as "custom" into
  // run.json and summary.json. `diverse resume` refuses a run that has it (the CLI has
  // not the caller's code); resume_run with the same hooks continues it.
  nlohmann::json custom = nullptr;
};

struct RunRequest {
  std::string task;                 // task name or path (resolve_task_path)
  std::string metric;               // "" = the task's metric; "shape", "md+shape", ...
  double shape_weight = 10.0;       // weight of the shape distance in "<metric>+shape"
  bool vary_shape = false;          // the shape scales are free parameters too (the
                                    // character file's [shape] parameters)
  DiversityOptions options;         // variations = 0 means the task's N, sigma0 = 0 its sigma0
  double strength = 1.0;            // the strength model: PD gains and torque limits times
                                    // this (Task::strength), in [kMinStrength, kMaxStrength]
  MotionBounds bounds;              // effort and distance bounds (eval/motion_problem.h)
  std::filesystem::path out;        // run directory
  int threads = 0;                  // 0 = one per core
  bool force = false;               // replace an existing run in `out`
  double checkpoint_seconds = 5.0;  // wall time between checkpoints
  bool render = true;               // write filmstrip.png at the end
  bool quiet = false;               // no progress output
  Cluster* cluster = nullptr;       // rank 0 of several (mpirun): rollouts spread over
                                    // every rank; threads = 0 then means this node's
                                    // cores shared among its ranks
  RunHooks hooks;                   // none by default
};

// Starts a run. Throws UserError on bad input or if `out` holds a run and !force.
void start_run(const RunRequest& request);

// Continues the run in `dir` from its checkpoint (threads: 0 = one per core). A run that
// already finished only has its outputs written again; one stopped before its first
// checkpoint starts again from run.json's settings. Throws UserError if `dir` is not
// a run directory, its checkpoint is corrupt, or its task file changed.
// `hooks` as in RunRequest: a run whose run.json has "custom" needs hooks.wrap_problem.
void resume_run(const std::filesystem::path& dir, int threads, bool quiet = false,
                double checkpoint_seconds = 5.0, bool render = true, Cluster* cluster = nullptr,
                const RunHooks& hooks = {});

// A rank other than 0 of `mpirun -n R diverse run|resume`: waits for rank 0's settings,
// builds the same problem from its own copy of the task's files (refusing, through rank
// 0, files that differ from rank 0's), evaluates rank 0's samples with `threads` threads
// (0 = this node's cores shared among its ranks) and returns when rank 0 ends.
void serve_run(Cluster& cluster, int threads);

// Removes the "timing" object: what must be identical between equivalent runs.
nlohmann::json without_timing(nlohmann::json summary);

}  // namespace diverse
