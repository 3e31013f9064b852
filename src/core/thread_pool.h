// A small fixed-size thread pool with one operation: parallel_for.
//
//   ThreadPool pool(threads);
//   std::vector<double> out(count);
//   pool.parallel_for(count, [&](std::size_t index, int worker) {
//     out[index] = work(index, scratch[worker]);
//   });
//
// `worker` is in [0, size()) and no two calls running at the same time share a worker
// index, so callers keep per-thread scratch (a MuJoCo mjData, a buffer) in a vector
// indexed by it. Results are meant to be written by `index`; which worker runs which
// index varies from run to run, so nothing a task computes may depend on `worker`
// beyond the choice of scratch. That is how results stay identical for any thread count.
//
// The calling thread takes part as worker 0, so a pool of size 1 starts no thread and
// runs everything inline, in index order. If tasks throw, parallel_for stops handing out
// new indices, waits for running tasks, and rethrows the exception of the lowest index
// that threw. A parallel_for called from inside a task of the same pool runs inline on
// that task's worker (no deadlock, no oversubscription). Calls from different external
// threads are serialized.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace diverse {

class ThreadPool {
 public:
  using Task = std::function<void(std::size_t index, int worker)>;

  // threads >= 1 (throws std::invalid_argument otherwise); starts threads - 1 threads.
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  // Number of workers, including the calling thread.
  int size() const { return size_; }

  // Runs fn(index, worker) for every index in [0, count) and returns when all are done.
  void parallel_for(std::size_t count, const Task& fn);

  // Hardware threads, at least 1.
  static int hardware_threads();

 private:
  void worker_main(int worker);
  void run_tasks(int worker);

  int size_ = 1;
  std::vector<std::thread> threads_;

  std::mutex call_mutex_;  // serializes parallel_for calls from outside the pool
  std::mutex mutex_;       // guards everything below
  std::condition_variable start_cv_;
  std::condition_variable done_cv_;
  const Task* task_ = nullptr;
  std::size_t count_ = 0;
  std::uint64_t epoch_ = 0;  // bumped once per parallel_for to wake the workers
  int running_ = 0;          // background workers still busy with the current epoch
  bool stop_ = false;
  std::exception_ptr error_;
  std::size_t error_index_ = 0;

  std::atomic<std::size_t> next_{0};
  std::atomic<bool> abort_{false};
};

}  // namespace diverse
