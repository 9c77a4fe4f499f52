#pragma once
// A minimal parallel loop for independent, deterministic work items: each item's result must not
// depend on which thread computes it, so results are identical for any thread count.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace primseg::detail {

/// Threads to use for `requested` (0: all hardware threads), at least 1.
inline unsigned thread_count(unsigned requested) {
  if (requested > 0) return requested;
  return std::max(1u, std::thread::hardware_concurrency());
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
  for (unsigned t = 1; t < threads; ++t) workers.emplace_back(run_chunk, t);
  run_chunk(0);
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
  for (unsigned t = 1; t < threads; ++t) workers.emplace_back(run, t);
  run(0);
  for (std::thread& w : workers) w.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace primseg::detail
