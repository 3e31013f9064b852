// A run's checkpoint.json: the file `diverse run` writes at generation boundaries and
// `diverse resume` continues from (run/run.h has the run directory around it).
//
//   {"format": "diverse.run_checkpoint", "wall_seconds": S, "vary": ["control"],
//    "optimizer": {...}}      DiversityOptimizer::checkpoint(), optimize/diversity.h
//
// The file is written atomically (io/files.h), so a kill at any moment leaves the
// previous checkpoint or the new one. Reading is strict: whatever is wrong with a file
// (unreadable, not JSON, another format, state that does not fit the run's problem, a
// state whose re-evaluated sets do not give their recorded D) is a UserError naming it.
#pragma once

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "core/thread_pool.h"
#include "optimize/diversity.h"

namespace diverse {

// The parameter groups a run varies, as run.json and checkpoint.json record them:
// ["control"] or ["control", "shape"].
nlohmann::json vary_json(bool vary_shape);

// The checkpoint file's JSON.
nlohmann::json run_checkpoint_json(double wall_seconds, bool vary_shape,
                                   const DiversityOptimizer& optimizer);

// Reads a run's checkpoint.json: the optimizer's state (DiversityOptimizer::
// from_checkpoint reads it) and the wall seconds spent before it was written. Throws
// UserError "FILE: FIELD: expected ..." if the file is unreadable, not JSON, not a
// checkpoint `diverse run` wrote, or its "vary" does not match `vary_shape`.
nlohmann::json read_run_checkpoint(const std::filesystem::path& file, bool vary_shape,
                                   double* wall_seconds);

// The optimizer restored from read_run_checkpoint()'s state. Every failure is a UserError
// naming `file`: a state that does not fit the problem or is malformed, and one whose
// re-evaluated sets do not reproduce their recorded D.
// `batch` as for DiversityOptimizer (nullptr: the pool evaluates).
std::unique_ptr<DiversityOptimizer> restore_optimizer(const DiversityProblem& problem,
                                                      const nlohmann::json& state, ThreadPool& pool,
                                                      const std::filesystem::path& file,
                                                      BatchEvaluator* batch = nullptr);

}  // namespace diverse
