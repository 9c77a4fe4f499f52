#pragma once
// Pages that a loop will write for the first time, faulted in a few MB ahead of it on a thread
// of their own.
//
// The merge loop appends to two large arrays, the merge records (128 bytes a merge) and the
// statistics pool (568 bytes a cluster of three faces or more), and is the first to touch each of
// their pages: about 300 MB for a million faces, each page a fault taken on the loop's thread. On
// a virtual machine a fresh 2 MB page costs milliseconds (the host backs it then: about 1.5 ms per
// MB on session 66's host, against 0.06 ms per MB for memory the guest has used before), and with
// the default primitive types the second core idles during the loop. There a PageWarmer faults the
// pages in (madvise MADV_POPULATE_WRITE, Linux 5.14 and later; elsewhere it does nothing) up to
// `lead_bytes` past what the loop has used so far, so the loop finds them present. No value
// changes, only who takes the faults and when; each array's resident size runs at most the lead
// (and one huge page) ahead of its use, and never past its capacity.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "huge_pages.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace primseg::detail {

class PageWarmer {
 public:
  /// An array's storage [begin, begin + capacity_bytes), of which the loop has used the first
  /// *used_bytes (stored by the loop's thread, read here; relaxed order suffices: a late value
  /// only delays the warming).
  struct Region {
    const void* begin = nullptr;
    std::size_t capacity_bytes = 0;
    const std::atomic<std::size_t>* used_bytes = nullptr;
  };

  /// Whether this system can fault pages in ahead (MADV_POPULATE_WRITE is known).
  static constexpr bool supported() {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    return true;
#else
    return false;
#endif
  }

  PageWarmer() = default;
  PageWarmer(const PageWarmer&) = delete;
  PageWarmer& operator=(const PageWarmer&) = delete;
  ~PageWarmer() {
    stop();
  }

  /// Starts warming the regions on a new thread (nothing if unsupported, or if the thread cannot
  /// be started: the loop then takes its faults itself). The regions' storage must stay mapped
  /// until stop() returns.
  void start(std::vector<Region> regions, std::size_t lead_bytes) {
    stop();
    if (!supported() || regions.empty()) return;
    regions_ = std::move(regions);
    lead_bytes_ = lead_bytes;
    stopping_ = false;
    try {
      thread_ = std::thread([this] { run(); });
    } catch (const std::system_error&) {
      // Like a system without the call: the faults stay with the loop.
    }
  }

  /// Stops the thread and waits for it (at most the call in progress, a lead's worth of pages).
  void stop() {
    if (!thread_.joinable()) return;
    {
      const std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }

  /// Bytes faulted in ahead so far (all regions; for tests).
  std::size_t warmed_bytes() const {
    return warmed_bytes_.load(std::memory_order_relaxed);
  }

 private:
  static constexpr std::uintptr_t kStep = std::uintptr_t{2} << 20;  // a huge page

  void run() {
    // Per region, the end of what is warmed; pages before the first 2 MB boundary are left to
    // the loop (they are few, and the range must start on a page).
    std::vector<std::uintptr_t> warmed(regions_.size());
    for (std::size_t r = 0; r < regions_.size(); ++r)
      warmed[r] = align_up(reinterpret_cast<std::uintptr_t>(regions_[r].begin));
    std::unique_lock lock(mutex_);
    while (!stopping_) {
      bool done = true;
      for (std::size_t r = 0; r < regions_.size() && !stopping_; ++r) {
        const Region& region = regions_[r];
        const auto begin = reinterpret_cast<std::uintptr_t>(region.begin);
        const std::uintptr_t end = (begin + region.capacity_bytes) & ~(kStep - 1);
        const std::size_t used = region.used_bytes->load(std::memory_order_relaxed);
        const std::uintptr_t target = std::min(end, align_up(begin + used + lead_bytes_));
        if (warmed[r] < end) done = false;
        if (warmed[r] >= target) continue;
        lock.unlock();
        const bool ok = populate(warmed[r], target - warmed[r]);
        lock.lock();
        if (!ok) return;  // an older kernel, or no memory: the loop takes its own faults
        warmed_bytes_.fetch_add(target - warmed[r], std::memory_order_relaxed);
        warmed[r] = target;
      }
      if (done) return;
      // The loop appends some kB per ms: a look every millisecond keeps the lead.
      wake_.wait_for(lock, std::chrono::milliseconds(1), [this] { return stopping_; });
    }
  }

  static std::uintptr_t align_up(std::uintptr_t address) {
    return (address + kStep - 1) & ~(kStep - 1);
  }

  static bool populate(std::uintptr_t start, std::size_t bytes) {
    return populate_pages(
        reinterpret_cast<const void*>(start),  // NOLINT(performance-no-int-to-ptr)
        bytes);
  }

  std::vector<Region> regions_;
  std::size_t lead_bytes_ = 0;
  std::atomic<std::size_t> warmed_bytes_{0};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace primseg::detail
