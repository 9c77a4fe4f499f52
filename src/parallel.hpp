#pragma once
// A minimal parallel loop for independent, deterministic work items: each item's result must not
// depend on which thread computes it, so results are identical for any thread count.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

namespace primseg::detail {

/// Most threads one parallel loop uses. Results are the same for any count, and beyond this many
/// threads only contend.
inline constexpr unsigned kMaxThreads = 256;

/// Threads to use for `requested` (0: all hardware threads), from 1 to kMaxThreads.
inline unsigned thread_count(unsigned requested) {
  if (requested > 0) return std::min(requested, kMaxThreads);
  return std::clamp(std::thread::hardware_concurrency(), 1u, kMaxThreads);
}

/// Starts `workers.emplace_back(start, t)` for t in [1, threads), until the system refuses a thread
/// (std::system_error: a process, thread or memory limit). Returns the number of threads that run,
/// the caller included: callers give the work of the others to those, which changes no result.
/// `workers` must have room for threads − 1 more without reallocating (reserve).
template <typename Start>
unsigned start_threads(std::vector<std::thread>& workers, unsigned threads, const Start& start) {
  for (unsigned t = 1; t < threads; ++t) {
    try {
      workers.emplace_back(start, t);
    } catch (const std::system_error&) {
      return t;
    }
  }
  return std::max(threads, 1u);
}

/// Calls body(i) for i in [0, count), in contiguous chunks on `threads` threads. The first
/// exception thrown by any chunk is rethrown after all threads have finished.
template <typename Body>
void parallel_for(std::size_t count, unsigned threads, Body&& body) {
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, count / 1024 + 1));
  if (threads <= 1) {
    for (std::size_t i = 0; i < count; ++i) body(i);
    return;
  }
  std::vector<std::exception_ptr> errors(threads);
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  auto run_chunk = [&](unsigned t) {
    try {
      const std::size_t begin = count * t / threads, end = count * (t + 1) / threads;
      for (std::size_t i = begin; i < end; ++i) body(i);
    } catch (...) {
      errors[t] = std::current_exception();
    }
  };
  const unsigned started = start_threads(workers, threads, run_chunk);
  run_chunk(0);
  for (unsigned t = started; t < threads; ++t) run_chunk(t);  // chunks no thread could take
  for (std::thread& w : workers) w.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

/// Calls body(i, thread) for i in [0, count), items handed out one at a time (for items of very
/// unequal cost), `thread` in [0, threads) naming the calling thread: per-thread scratch space.
/// The first exception thrown is rethrown after all threads have finished.
template <typename Body>
void parallel_for_threads(std::size_t count, unsigned threads, Body&& body) {
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, count));
  if (threads <= 1) {
    for (std::size_t i = 0; i < count; ++i) body(i, 0u);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::vector<std::exception_ptr> errors(threads);
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  auto run = [&](unsigned t) {
    try {
      for (std::size_t i; (i = next.fetch_add(1)) < count;) body(i, t);
    } catch (...) {
      errors[t] = std::current_exception();
      next = count;
    }
  };
  start_threads(workers, threads, run);
  run(0);
  for (std::thread& w : workers) w.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace primseg::detail
