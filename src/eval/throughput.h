// Throughput measurements behind `diverse bench` (all figures measured in one run, as
// ratios, so they compare across machines).
//
//   raw mj_step     plain mj_step on the task's model replaying M0's recorded inputs:
//                   the same physics work as a rollout of M0, without any controller
//   rollout         TaskEvaluator::evaluate of M0 as the optimizer runs it: control,
//                   contact scans, constraint bookkeeping and pose recording included
//   parallel        a batch of perturbed M0 samples evaluated on a thread pool with 1
//                   thread and with `threads` threads; speed-up = time(1) / time(threads)
#pragma once

#include <nlohmann/json.hpp>

#include "task/evaluate.h"

namespace diverse {

struct ThroughputOptions {
  double seconds = 2.0;  // wall time to spend on each single-thread measurement
  int threads = 0;       // for the parallel measurement; 0 = one per core
  int batch = 64;        // samples per parallel batch
};

struct ThroughputReport {
  double raw_steps_per_second = 0;
  double rollout_steps_per_second = 0;
  double rollout_ratio = 0;       // rollout / raw
  int rollout_steps = 0;          // steps in one rollout of M0
  double rollouts_per_second_1 = 0;
  double rollouts_per_second_n = 0;
  int threads = 1;
  double speedup = 0;             // rollouts_per_second_n / rollouts_per_second_1
  nlohmann::json to_json() const;
};

ThroughputReport measure_throughput(const TaskEvaluator& evaluator, const ParameterSet& m0,
                                    const ThroughputOptions& options);

// A character with a free root standing under stance control (control/stance_controller.h)
// from its standing pose for `standing_seconds` of simulated time: rollout (stance control
// through the joint drive) against raw mj_step replaying the same inputs, interleaved.
// Fills the raw, rollout and rollouts/s (1 thread) figures. Throws UserError for a file
// that is not a character with a free root.
ThroughputReport measure_stance_throughput(const std::string& character_file,
                                           const ThroughputOptions& options,
                                           double standing_seconds = 3.0);

}  // namespace diverse
