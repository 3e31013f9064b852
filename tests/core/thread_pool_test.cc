#include "core/thread_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace diverse {
namespace {

// Work whose result depends only on the index, so any thread count must agree.
double work(std::size_t index) {
  double x = static_cast<double>(index) + 0.5;
  for (int k = 0; k < 200; ++k) x = std::sin(x) + 0.001 * static_cast<double>(k);
  return x;
}

TEST(ThreadPool, RejectsFewerThanOneThread) {
  EXPECT_THROW(ThreadPool(0), std::invalid_argument);
  EXPECT_THROW(ThreadPool(-3), std::invalid_argument);
}

TEST(ThreadPool, RunsEveryIndexExactlyOnceWithWorkerInRange) {
  for (int threads : {1, 2, 3, 5}) {
    ThreadPool pool(threads);
    EXPECT_EQ(pool.size(), threads);
    const std::size_t count = 1000;
    std::vector<std::atomic<int>> hits(count);
    std::atomic<int> bad_worker{0};
    pool.parallel_for(count, [&](std::size_t i, int worker) {
      hits[i].fetch_add(1);
      if (worker < 0 || worker >= threads) bad_worker.fetch_add(1);
    });
    for (std::size_t i = 0; i < count; ++i) EXPECT_EQ(hits[i].load(), 1) << "index " << i;
    EXPECT_EQ(bad_worker.load(), 0);
  }
}

TEST(ThreadPool, ResultsAreIdenticalForAnyThreadCount) {
  const std::size_t count = 257;
  std::vector<double> reference(count);
  for (std::size_t i = 0; i < count; ++i) reference[i] = work(i);
  for (int threads : {1, 2, 3, 4}) {
    ThreadPool pool(threads);
    std::vector<double> out(count, 0.0);
    // Several rounds reuse the same pool.
    for (int round = 0; round < 5; ++round) {
      pool.parallel_for(count, [&](std::size_t i, int) { out[i] = work(i); });
      EXPECT_EQ(out, reference) << threads << " threads, round " << round;
    }
  }
}

TEST(ThreadPool, NoTwoTasksShareAWorkerAtTheSameTime) {
  const int threads = 3;
  ThreadPool pool(threads);
  std::vector<std::atomic<int>> in_use(threads);
  std::atomic<int> clashes{0};
  pool.parallel_for(300, [&](std::size_t i, int worker) {
    if (in_use[worker].fetch_add(1) != 0) clashes.fetch_add(1);
    volatile double sink = work(i);
    (void)sink;
    in_use[worker].fetch_sub(1);
  });
  EXPECT_EQ(clashes.load(), 0);
}

TEST(ThreadPool, ZeroCountDoesNothing) {
  ThreadPool pool(2);
  int calls = 0;
  pool.parallel_for(0, [&](std::size_t, int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(ThreadPool, ExceptionOfLowestThrowingIndexReachesCaller) {
  for (int threads : {1, 2, 3}) {
    ThreadPool pool(threads);
    try {
      // Only index 7 throws, so the same exception must surface for every thread count.
      pool.parallel_for(50, [&](std::size_t i, int) {
        if (i == 7) throw std::runtime_error("task " + std::to_string(i) + " failed");
      });
      FAIL() << "no exception with " << threads << " threads";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "task 7 failed");
    }
    // The pool stays usable after an exception.
    std::vector<int> out(10, 0);
    pool.parallel_for(10, [&](std::size_t i, int) { out[i] = static_cast<int>(i) * 2; });
    for (int i = 0; i < 10; ++i) EXPECT_EQ(out[i], 2 * i);
  }
}

TEST(ThreadPool, SerialPoolReportsFirstThrowingIndex) {
  ThreadPool pool(1);
  try {
    pool.parallel_for(10, [](std::size_t i, int) {
      if (i >= 3) throw std::runtime_error("index " + std::to_string(i));
    });
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "index 3");
  }
}

TEST(ThreadPool, NestedCallRunsInlineOnTheSameWorker) {
  ThreadPool pool(2);
  std::vector<std::vector<int>> out(8, std::vector<int>(4, -1));
  std::atomic<int> worker_mismatch{0};
  pool.parallel_for(8, [&](std::size_t i, int worker) {
    pool.parallel_for(4, [&](std::size_t j, int inner_worker) {
      if (inner_worker != worker) worker_mismatch.fetch_add(1);
      out[i][j] = static_cast<int>(i * 10 + j);
    });
  });
  EXPECT_EQ(worker_mismatch.load(), 0);
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_EQ(out[i][j], i * 10 + j);
}

}  // namespace
}  // namespace diverse
