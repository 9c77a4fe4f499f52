#pragma once
// Batches of independent jobs on the calling thread and a few persistent helper threads.
//
// The merge loop evaluates batches of candidates, a microsecond or more each, many times a second:
// starting threads per batch (tens of microseconds) would cost more than the work. Helpers
// therefore spin for a while after each batch and only then sleep (std::atomic::wait), so they
// stay awake while batches follow each other and release their core once the loop ends. Each
// job is claimed with an atomic operation on a line the caller also writes, about 130 ns when the
// threads run on cores that share no cache: batches of a few short jobs are faster on the
// caller alone (run()'s parallel_from; HierarchyBuilder shares a merge's five or so candidates
// only when their fits are costly).
//
// The caller never waits for a helper to show up: jobs are claimed one at a time from a cursor
// tagged with the batch's number, the caller claims them too, and it waits only for jobs a helper
// has claimed and is running. A helper that was not scheduled during a batch (other processes on
// the cores) finds the cursor moved on and claims nothing of it, so an overloaded machine slows
// the build down gracefully instead of stalling it.
//
// Each job's result must not depend on which thread runs it; callers write results to distinct
// slots and apply them in order afterwards, so the outcome is the same for any thread count.

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "parallel.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace primseg::detail {

class BatchPool {
 public:
  /// A pool for `threads` threads in all: the caller and threads − 1 helpers (none for 0 or 1),
  /// or fewer helpers if the system refuses to start them all (thread_count() tells).
  explicit BatchPool(unsigned threads) {
    helpers_.reserve(threads > 1 ? threads - 1 : 0);
    start_threads(helpers_, threads, [this](unsigned t) { serve(t); });
  }
  ~BatchPool() {
    stopping_.store(true, std::memory_order_seq_cst);
    wake_.fetch_add(1, std::memory_order_seq_cst);
    wake_.notify_all();
    for (std::thread& h : helpers_) h.join();
  }
  BatchPool(const BatchPool&) = delete;
  BatchPool& operator=(const BatchPool&) = delete;

  /// Threads that run jobs, the caller included.
  unsigned thread_count() const { return static_cast<unsigned>(helpers_.size()) + 1; }

  /// Calls job(i, thread) for every i in [0, count) (count < 2^32) and returns when all calls
  /// have returned; `thread` in [0, thread_count()) names the calling thread (0: the caller), for
  /// per-thread scratch space. The first exception a job throws is rethrown here once all are
  /// done. Batches of fewer than `parallel_from` jobs (at least 2) run on the caller alone, in
  /// order: for short jobs the hand-off costs more than it saves. Not reentrant: one caller at a
  /// time.
  template <typename Job>
  void run(std::size_t count, Job& job, std::size_t parallel_from = 2) {
    if (helpers_.empty() || count < std::max<std::size_t>(parallel_from, 2)) {
      for (std::size_t i = 0; i < count; ++i) job(i, 0u);
      return;
    }
    const std::uint32_t batch = ++batch_number_;
    Batch& b = batches_[batch % batches_.size()];
    b.job.store(&job, std::memory_order_relaxed);
    b.invoke.store([](void* context, std::size_t i,
                      unsigned thread) { (*static_cast<Job*>(context))(i, thread); },
                   std::memory_order_relaxed);
    b.count.store(count, std::memory_order_relaxed);
    b.done.store(0, std::memory_order_relaxed);
    cursor_.store(std::uint64_t{batch} << 32, std::memory_order_release);
    // Sequentially consistent with serve()'s sleeping_ increment and wait: either this sees a
    // helper asleep and wakes it, or the helper's wait sees the new value.
    wake_.fetch_add(1, std::memory_order_seq_cst);
    if (sleeping_.load(std::memory_order_seq_cst) > 0) wake_.notify_all();
    work(0);
    for (int spin = 0; b.done.load(std::memory_order_acquire) != count; ++spin)
      if (spin < kSpins)
        pause();
      else
        std::this_thread::yield();  // the helper running the last job was descheduled
    if (error_) {
      std::exception_ptr error = std::move(error_);
      error_ = nullptr;
      std::rethrow_exception(error);
    }
  }

 private:
  // About 50 µs of spinning (a pause is about 10-40 ns) before sleeping or yielding.
  static constexpr int kSpins = 4096;

  struct Batch {
    std::atomic<void*> job{nullptr};
    std::atomic<void (*)(void*, std::size_t, unsigned)> invoke{nullptr};
    std::atomic<std::size_t> count{0};
    std::atomic<std::size_t> done{0};
  };

  static void pause() {
#if defined(__x86_64__) || defined(__i386__)
    _mm_pause();
#else
    std::this_thread::yield();
#endif
  }

  // Claims and runs jobs of the current batch until none is left; false if there was none.
  bool work(unsigned thread) {
    bool worked = false;
    for (;;) {
      std::uint64_t cursor = cursor_.load(std::memory_order_acquire);
      const auto batch = static_cast<std::uint32_t>(cursor >> 32);
      const auto index = static_cast<std::uint32_t>(cursor);
      Batch& b = batches_[batch % batches_.size()];
      // The count may belong to a later batch if this thread lags; then the claim below fails,
      // since the cursor's batch number has changed.
      if (index >= b.count.load(std::memory_order_relaxed)) return worked;
      if (!cursor_.compare_exchange_weak(cursor, cursor + 1, std::memory_order_acq_rel)) continue;
      // Claimed: the batch cannot end before this job does, so its fields are this batch's.
      try {
        b.invoke.load(std::memory_order_relaxed)(b.job.load(std::memory_order_relaxed), index,
                                                 thread);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex_);
        if (!error_) error_ = std::current_exception();
      }
      b.done.fetch_add(1, std::memory_order_release);
      worked = true;
    }
  }

  void serve(unsigned thread) {
    std::uint32_t seen = wake_.load(std::memory_order_acquire);
    for (;;) {
      if (stopping_.load(std::memory_order_acquire)) return;
      work(thread);
      int spin = 0;
      std::uint32_t now = wake_.load(std::memory_order_acquire);
      for (; now == seen && spin < kSpins; ++spin) {
        pause();
        now = wake_.load(std::memory_order_acquire);
      }
      if (now == seen) {
        sleeping_.fetch_add(1, std::memory_order_seq_cst);
        wake_.wait(seen, std::memory_order_seq_cst);
        sleeping_.fetch_sub(1, std::memory_order_seq_cst);
        now = wake_.load(std::memory_order_acquire);
      }
      seen = now;
    }
  }

  std::vector<std::thread> helpers_;
  std::array<Batch, 2> batches_;
  std::uint32_t batch_number_ = 0;  // the caller's only
  // (batch number << 32) | index of the next unclaimed job.
  std::atomic<std::uint64_t> cursor_{0};
  std::atomic<std::uint32_t> wake_{0};
  std::atomic<unsigned> sleeping_{0};
  std::atomic<bool> stopping_{false};
  std::mutex error_mutex_;
  std::exception_ptr error_;
};

}  // namespace primseg::detail
