// The helper-thread pool runs every job exactly once, on thread indices in range, for batches of
// any size, rethrows a job's exception, and needs no helper to show up (an overloaded machine).
// The pool and the parallel loops (parallel.hpp) run on the threads the system starts, if it
// refuses some.
#include "batch_pool.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "parallel.hpp"
#include "support/test_support.hpp"

namespace primseg::detail {
namespace {

TEST(BatchPool, RunsEveryJobOnceForAnyBatchSizeAndThreadCount) {
  for (unsigned threads : {1u, 2u, 3u, 8u}) {
    BatchPool pool(threads);
    ASSERT_EQ(pool.thread_count(), threads);
    for (std::size_t count : {0, 1, 2, 3, 5, 17, 1000, 100000}) {
      std::vector<std::atomic<int>> runs(count);
      std::atomic<bool> thread_in_range{true};
      auto job = [&](std::size_t i, unsigned thread) {
        runs[i].fetch_add(1);
        if (thread >= pool.thread_count()) thread_in_range = false;
      };
      pool.run(count, job);
      for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(runs[i].load(), 1) << i;
      EXPECT_TRUE(thread_in_range);
    }
  }
}

// Below parallel_from a batch runs on the caller alone, in order; from it, on any thread.
TEST(BatchPool, ABatchSmallerThanParallelFromRunsOnTheCallerInOrder) {
  BatchPool pool(2);
  std::vector<std::size_t> order;
  bool only_caller = true;
  auto job = [&](std::size_t i, unsigned thread) {
    order.push_back(i);
    only_caller = only_caller && thread == 0;
  };
  pool.run(31, job, 32);
  EXPECT_TRUE(only_caller);
  ASSERT_EQ(order.size(), 31u);
  for (std::size_t i = 0; i < order.size(); ++i) EXPECT_EQ(order[i], i);
  std::vector<std::atomic<int>> runs(32);
  auto counted = [&](std::size_t i, unsigned) { runs[i].fetch_add(1); };
  pool.run(32, counted, 32);
  for (std::size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i].load(), 1) << i;
}

TEST(BatchPool, ManySmallBatchesInARow) {
  BatchPool pool(2);
  std::vector<double> results(6);
  double total = 0;
  for (int batch = 0; batch < 200000; ++batch) {
    auto job = [&](std::size_t i, unsigned) { results[i] = double(batch) * double(i); };
    pool.run(results.size(), job);
    for (std::size_t i = 0; i < results.size(); ++i)
      ASSERT_EQ(results[i], double(batch) * double(i));
    total += results[5];
  }
  EXPECT_GT(total, 0);
}

TEST(BatchPool, RethrowsAJobsExceptionAfterTheBatch) {
  BatchPool pool(2);
  std::atomic<int> runs{0};
  auto job = [&](std::size_t i, unsigned) {
    runs.fetch_add(1);
    if (i == 3) throw std::runtime_error("job 3 failed");
  };
  EXPECT_THROW(pool.run(10, job), std::runtime_error);
  EXPECT_EQ(runs.load(), 10);
  // The pool is usable afterwards.
  auto fine = [&](std::size_t, unsigned) { runs.fetch_add(1); };
  pool.run(10, fine);
  EXPECT_EQ(runs.load(), 20);
}

TEST(Threads, ThreadCountsAreBounded) {
  EXPECT_EQ(thread_count(3), 3u);
  EXPECT_EQ(thread_count(100000), kMaxThreads);
  EXPECT_GE(thread_count(0), 1u);
  EXPECT_LE(thread_count(0), kMaxThreads);
}

// Before, a refused thread (std::system_error) ended the process in std::terminate: `primseg
// segment --threads 100000`.
TEST(Threads, WorkRunsOnTheThreadsThatStartedWhenTheSystemRefusesOthers) {
  const testing::RefuseNewThreads refused;
  BatchPool pool(8);
  EXPECT_EQ(pool.thread_count(), 1u);
  std::vector<int> runs(1000, 0);
  auto job = [&](std::size_t i, unsigned thread) { runs[i] += thread == 0 ? 1 : 100; };
  pool.run(runs.size(), job);
  parallel_for(100000, 4, [&](std::size_t i) { runs[i % runs.size()] += 1000; });
  parallel_for_threads(
      runs.size(), 4, [&](std::size_t i, unsigned thread) { runs[i] += thread == 0 ? 100000 : 1; });
  for (std::size_t i = 0; i < runs.size(); ++i) ASSERT_EQ(runs[i], 1 + 100 * 1000 + 100000) << i;
}

}  // namespace
}  // namespace primseg::detail
