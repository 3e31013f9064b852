// A run's rollouts spread over several processes with MPI (SPEC section 11):
//
//   mpirun -n R diverse run TASK ...        mpirun -n R diverse resume DIR
//
// Rank 0 is the run: it parses the command, runs the optimizer, writes checkpoints and the
// run directory exactly as a single process does. Ranks 1..R-1 only evaluate samples, each
// with its own threads, and exit when rank 0 ends. Results are bit-identical to one
// process with the same seed: every outcome lands in its batch slot, whoever computed it.
//
// Protocol (MPI_COMM_WORLD, point to point, rank 0 <-> each worker; tags in cluster_mpi.cc):
//   1. setup   0 -> w   the text that lets a worker build the same problem (run/run.cc sends
//                       the task file's path and text, metric, shape setting, version and
//                       M0's parameters); the worker checks them against its own files
//      ready   w -> 0   "THREADS HOST"          or
//      refuse  w -> 0   a one-line reason (rank 0 ends the run with it, naming rank and host)
//   2. per batch of n samples (DiversityOptimizer's batches, optimize/batch_evaluator.h):
//      task    0 -> w   [batch u64][slot u64][0 u64][x: dim doubles]  normalized parameters
//      result  w -> 0   [batch u64][slot u64][ns u64][outcome bytes]  MotionProblem::encode,
//                       ns: the worker's time in evaluate()
//      fail    w -> 0   [batch u64][slot u64][0 u64][one-line reason]
//      beat    w -> 0   [0 u64][0 u64][0 u64]  a worker holding tasks that has sent nothing
//                       for 0.5 s (a long rollout): it is alive
//      Work is handed out dynamically: each worker holds at most as many tasks as it has
//      threads, gets the next free slot when a result comes back, and rank 0's own thread
//      pool takes slots from the same counter. A batch ends when every slot is filled.
//   3. stop    0 -> w   rank 0 is ending (finished, failed, or refused its input); the
//                       worker finishes its threads and exits 0.
// Nobody blocks in MPI while waiting: both sides poll (MPI_Iprobe) with short sleeps, so
// an idle rank leaves its core to the ranks that compute.
//
// Failures. A worker whose evaluation throws sends `fail`; rank 0 ends the run with a
// ClusterError. A worker that holds tasks (or owes its setup answer) and says nothing
// for the rank timeout (set_rank_timeout, `--rank-timeout`, 30 s by default) is lost: it
// was stopped, hangs, or its node or the network went away without mpirun noticing.
// Rank 0 ends the run with a ClusterError naming the rank, leaves without MPI_Finalize
// (which would wait for the lost rank), and mpirun, seeing rank 0 exit 2, stops the
// others and exits 2 too. A worker that dies (killed, out of memory) makes mpirun stop
// every rank at once: rank 0 then prints one line naming that, the run directory and the
// last checkpoint's generation (`diverse resume DIR` continues from it), and exits 2;
// mpirun itself reports which rank died and exits with that rank's status (137 for
// SIGKILL: Open MPI 4 decides that, not diverse). The checkpoint is written atomically,
// so it is always whole.
//
// Without MPI (a build configured where Open MPI is not installed), join() returns
// nullptr for a process started on its own and throws UserError for one that mpirun
// started among several ranks.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/thread_pool.h"
#include "optimize/batch_evaluator.h"
#include "optimize/objective.h"

namespace diverse {

// A failure of another rank of the run (not of the user's files).
class ClusterError : public UserError {
 public:
  using UserError::UserError;
};

// True when this build was configured with MPI.
bool cluster_support();

// How long rank 0 waits for a word from a worker that holds tasks (see Failures above).
constexpr double kDefaultRankTimeoutSeconds = 30.0;
constexpr double kMinRankTimeoutSeconds = 2.0;  // workers beat every 0.5 s

class Cluster {
 public:
  using Decode = std::function<std::shared_ptr<const Outcome>(const std::string& bytes)>;
  using Encode = std::function<std::string(const Outcome& outcome)>;

  // Joins the ranks mpirun started when there are several (OMPI_COMM_WORLD_SIZE > 1);
  // nullptr otherwise. Throws UserError if there are several and this build has no MPI.
  static std::unique_ptr<Cluster> join();
  // Rank 0 tells every worker to stop (if it has not); then MPI ends.
  ~Cluster();
  Cluster(const Cluster&) = delete;
  Cluster& operator=(const Cluster&) = delete;

  int rank() const;
  int size() const;
  // Rank 0: seconds without a word from a worker holding tasks before the run ends with a
  // ClusterError naming it (>= kMinRankTimeoutSeconds; std::invalid_argument otherwise).
  void set_rank_timeout(double seconds);
  // Threads for --threads 0: this node's hardware threads shared among its ranks.
  int default_threads() const;

  // --- rank 0 ---
  // Sends `setup` to every worker and waits until each has built its problem. Throws
  // ClusterError "rank R (HOST): REASON" for a worker that could not.
  void start_workers(const std::string& setup);
  // Evaluates batches of `problem` over every rank (this one on `pool`); results from
  // workers go through `decode`. Needs start_workers() first. Keeps references.
  std::unique_ptr<BatchEvaluator> evaluator(const DiversityProblem& problem, ThreadPool& pool,
                                            Decode decode);
  // The line printed (to stderr, then exit 2) if mpirun stops this rank with SIGTERM or
  // SIGINT, e.g. because a worker died. Async-signal-safe to print; any length.
  void set_stop_message(const std::string& line);
  // What went over the wire so far, for measurements (summary.json "timing"): tasks sent
  // to workers, their bytes and the results' bytes, and per remote evaluation the time
  // from sending its task to receiving its result beside the time the worker spent in
  // evaluate(); the difference is what messaging costs a rollout.
  struct Traffic {
    long long tasks = 0;
    long long task_bytes = 0;
    long long result_bytes = 0;
    double round_trip_seconds = 0;
    double compute_seconds = 0;
    std::vector<double> compute_ms;  // each remote evaluation's time in evaluate()
  };
  Traffic traffic() const;

  // --- ranks > 0 ---
  // Waits for rank 0's setup; returns false if rank 0 said stop first.
  bool receive_setup(std::string* setup);
  // Tells rank 0 that setup failed (one line), then waits for its stop.
  void refuse_setup(const std::string& reason);
  // Tells rank 0 this worker is ready with `threads` threads and evaluates its tasks with
  // encode(problem.evaluate(x, worker)) until rank 0 says stop.
  void serve(const DiversityProblem& problem, int threads, Encode encode);

  struct Impl;

 private:
  explicit Cluster(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace diverse
