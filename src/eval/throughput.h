// Throughput measurements behind `diverse bench` (all figures measured in one run, as
// ratios, so they compare across machines).
//
//   raw mj_step     plain mj_step on the task's model replaying M0's recorded inputs:
//                   the same physics work as a rollout of M0, without any controller
//   rollout         TaskEvaluator::evaluate of M0 as the optimizer runs it: control,
//                   contact scans, constraint bookkeeping and pose recording included
//   parallel        a batch of perturbed M0 samples evaluated on a thread pool with 1
//                   thread and with `threads` threads; speed-up = rate(threads) / rate(1)
//
// Robust to a shared machine: the measurements run interleaved in `rounds` short rounds
// (the order reversed every other round, so a drift in the machine's load hits both sides
// alike); within a round raw and rollout alternate one run at a time, so even a change
// of speed lasting a second or two cancels in their ratio. Each round gives its own ratio
// and speed-up, and the report has their median and spread. Raw and rollout rates count
// the measuring thread's CPU time (CLOCK_THREAD_CPUTIME_ID), so time the thread spent
// descheduled by other jobs counts against neither. The speed-up is wall time (what
// threads buy) and comes with the share of the threads' cores the process actually got
// while it ran (process CPU time / (wall time x threads)): below about 95 % other jobs
// held the cores, and the speed-up understates what the threads do on a free machine. A
// second speed-up, from CPU time, estimates that: each batch counts as long as its
// busiest thread's CPU time.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "task/evaluate.h"

namespace diverse {

struct ThroughputOptions {
  double seconds = 0.5;  // wall time of each measurement in each round (raw and rollout
                         // alternating: 2 x seconds for the two together)
  int threads = 0;       // for the parallel measurement; 0 = one per core
  int batch = 64;        // samples per parallel batch
  int rounds = 7;        // >= 1
};

// A figure measured once per round: the median and how far the rounds spread.
struct Spread {
  std::vector<double> rounds;  // in round order
  double median = 0, min = 0, max = 0;
  double q1 = 0, q3 = 0;       // quartiles (linear interpolation between rounds)
  static Spread of(std::vector<double> values);
  nlohmann::json to_json() const;
};

struct ThroughputReport {
  int rounds = 0;
  double seconds = 0;                   // per measurement per round
  int rollout_steps = 0;                // steps in one rollout of M0
  // Medians over the rounds; steps per CPU second of the measuring thread.
  double raw_steps_per_second = 0;
  double rollout_steps_per_second = 0;
  double rollout_ratio = 0;             // median of the rounds' rollout / raw
  Spread ratio;
  double rollouts_per_second_1 = 0;     // wall
  double rollouts_per_second_n = 0;     // wall
  int threads = 1;
  double speedup = 0;                   // median of the rounds' rate(threads) / rate(1)
  Spread speedup_spread;
  Spread cpu_share;                     // share of `threads` cores the process got, n threads
  // The speed-up free cores would give, from CPU time: each batch counted as long as its
  // busiest thread's CPU time (contention and the batch's uneven end count; time spent
  // descheduled by other jobs does not).
  Spread speedup_cpu;
  double load_before = -1, load_after = -1;  // 1-minute load average (-1: unknown)
  nlohmann::json to_json() const;
};

ThroughputReport measure_throughput(const TaskEvaluator& evaluator, const ParameterSet& m0,
                                    const ThroughputOptions& options);

// A character with a free root standing under stance control (control/stance_controller.h)
// from its standing pose for `standing_seconds` of simulated time: rollout (stance control
// through the joint drive) against raw mj_step replaying the same inputs, interleaved in
// rounds as above. Fills the raw, rollout and rollouts/s (1 thread) figures. Throws
// UserError for a file that is not a character with a free root.
ThroughputReport measure_stance_throughput(const std::string& character_file,
                                           const ThroughputOptions& options,
                                           double standing_seconds = 3.0);

}  // namespace diverse
