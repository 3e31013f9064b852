#include "core/thread_pool.h"

#include <stdexcept>
#include <string>

namespace diverse {
namespace {

// The pool and worker index of the task running on this thread, if any; lets a nested
// parallel_for run inline instead of waiting on workers that are busy with its caller.
thread_local const ThreadPool* t_pool = nullptr;
thread_local int t_worker = 0;

struct CurrentWorker {
  CurrentWorker(const ThreadPool* pool, int worker) : saved_pool(t_pool), saved_worker(t_worker) {
    t_pool = pool;
    t_worker = worker;
  }
  ~CurrentWorker() {
    t_pool = saved_pool;
    t_worker = saved_worker;
  }
  const ThreadPool* saved_pool;
  int saved_worker;
};

}  // namespace

ThreadPool::ThreadPool(int threads) : size_(threads) {
  if (threads < 1) {
    throw std::invalid_argument("ThreadPool: threads must be >= 1, got " + std::to_string(threads));
  }
  threads_.reserve(threads - 1);
  for (int w = 1; w < threads; ++w) threads_.emplace_back([this, w] { worker_main(w); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_cv_.notify_all();
  for (auto& t : threads_) t.join();
}

int ThreadPool::hardware_threads() {
  const unsigned n = std::thread::hardware_concurrency();
  return n == 0 ? 1 : static_cast<int>(n);
}

void ThreadPool::run_tasks(int worker) {
  CurrentWorker current(this, worker);
  while (!abort_.load(std::memory_order_relaxed)) {
    const std::size_t index = next_.fetch_add(1, std::memory_order_relaxed);
    if (index >= count_) break;
    try {
      (*task_)(index, worker);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_ || index < error_index_) {
        error_ = std::current_exception();
        error_index_ = index;
      }
      abort_.store(true, std::memory_order_relaxed);
    }
  }
}

void ThreadPool::worker_main(int worker) {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_cv_.wait(lock, [&] { return stop_ || epoch_ != seen; });
      if (stop_) return;
      seen = epoch_;
    }
    run_tasks(worker);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      --running_;
    }
    done_cv_.notify_one();
  }
}

void ThreadPool::parallel_for(std::size_t count, const Task& fn) {
  if (count == 0) return;
  // Nested call from one of our own tasks, or nothing to parallelize: run inline.
  if (t_pool == this || size_ == 1) {
    const int worker = t_pool == this ? t_worker : 0;
    CurrentWorker current(this, worker);
    for (std::size_t i = 0; i < count; ++i) fn(i, worker);
    return;
  }

  std::lock_guard<std::mutex> call_lock(call_mutex_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    task_ = &fn;
    count_ = count;
    next_.store(0, std::memory_order_relaxed);
    abort_.store(false, std::memory_order_relaxed);
    error_ = nullptr;
    error_index_ = 0;
    running_ = size_ - 1;
    ++epoch_;
  }
  start_cv_.notify_all();
  run_tasks(0);
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    done_cv_.wait(lock, [&] { return running_ == 0; });
    task_ = nullptr;
    error = error_;
    error_ = nullptr;
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace diverse
