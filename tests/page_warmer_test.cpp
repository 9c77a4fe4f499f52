#include "page_warmer.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace primseg::detail {
namespace {

#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
constexpr std::size_t kMB = std::size_t{1} << 20;

// An anonymous mapping nothing has touched yet, unmapped on destruction.
struct FreshMapping {
  explicit FreshMapping(std::size_t size) : bytes(size) {
    void* p = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    data = p == MAP_FAILED ? nullptr : static_cast<char*>(p);
  }
  ~FreshMapping() {
    if (data != nullptr) munmap(data, bytes);
  }
  FreshMapping(const FreshMapping&) = delete;
  FreshMapping& operator=(const FreshMapping&) = delete;

  // Whether the page holding data + offset is resident.
  bool resident(std::size_t offset) const {
    const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    unsigned char flag = 0;
    char* start = data + offset / page * page;
    return mincore(start, page, &flag) == 0 && (flag & 1) != 0;
  }

  char* data = nullptr;
  std::size_t bytes;
};

// Waits up to 5 s for the warmer to have warmed at least `bytes`.
bool warmed_at_least(const PageWarmer& warmer, std::size_t bytes) {
  for (int i = 0; i < 5000 && warmer.warmed_bytes() < bytes; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return warmer.warmed_bytes() >= bytes;
}

// Pages run the lead ahead of the use, follow it as it grows, and never pass the capacity; the
// memory reads as zeros (faulting in writes nothing).
TEST(PageWarmer, KeepsTheLeadAheadOfTheUseAndStopsAtTheCapacity) {
  constexpr std::size_t kSize = 64 * kMB;
  FreshMapping region(kSize);
  ASSERT_NE(region.data, nullptr);
  // The warmer works from the first 2 MB boundary: offsets below are relative to it.
  const auto begin = reinterpret_cast<std::uintptr_t>(region.data);
  const std::size_t skip = ((begin + 2 * kMB - 1) & ~(2 * kMB - 1)) - begin;
  const std::size_t capacity = skip + 40 * kMB;  // the array's capacity: 40 MB past the boundary

  std::atomic<std::size_t> used{0};
  PageWarmer warmer;
  warmer.start({{region.data, capacity, &used}}, 8 * kMB);
  if (!warmed_at_least(warmer, 8 * kMB)) GTEST_SKIP() << "MADV_POPULATE_WRITE refused (kernel)";
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // it must stop at the lead
  EXPECT_EQ(warmer.warmed_bytes(), 8 * kMB);
  EXPECT_TRUE(region.resident(skip));
  EXPECT_TRUE(region.resident(skip + 8 * kMB - 1));
  EXPECT_FALSE(region.resident(skip + 8 * kMB + 4096));

  used.store(skip + 16 * kMB);  // the use grows: the lead follows it
  ASSERT_TRUE(warmed_at_least(warmer, 24 * kMB));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(warmer.warmed_bytes(), 24 * kMB);
  EXPECT_TRUE(region.resident(skip + 24 * kMB - 1));
  EXPECT_FALSE(region.resident(skip + 24 * kMB + 4096));

  used.store(capacity);  // near the end: up to the capacity and no further
  ASSERT_TRUE(warmed_at_least(warmer, 40 * kMB));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(warmer.warmed_bytes(), 40 * kMB);
  EXPECT_FALSE(region.resident(capacity + 4096));
  warmer.stop();
  for (std::size_t offset = 0; offset < capacity; offset += 4096) ASSERT_EQ(region.data[offset], 0);
}

// Stopping returns promptly with work left, and a stopped warmer can be started again.
TEST(PageWarmer, StopsWithWorkLeftAndStartsAgain) {
  FreshMapping region(64 * kMB);
  ASSERT_NE(region.data, nullptr);
  std::atomic<std::size_t> used{0};
  PageWarmer warmer;
  warmer.start({{region.data, 64 * kMB, &used}}, 2 * kMB);
  if (!warmed_at_least(warmer, 2 * kMB)) GTEST_SKIP() << "MADV_POPULATE_WRITE refused (kernel)";
  const auto start = std::chrono::steady_clock::now();
  warmer.stop();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
  const std::size_t warmed = warmer.warmed_bytes();
  EXPECT_LT(warmed, 62 * kMB);
  used.store(32 * kMB);
  warmer.start({{region.data, 64 * kMB, &used}}, 2 * kMB);
  EXPECT_TRUE(warmed_at_least(warmer, warmed + 30 * kMB));
}
#endif

// A warmer never started, or started with nothing to warm, stops at once.
TEST(PageWarmer, NothingToWarm) {
  PageWarmer idle;
  idle.stop();
  std::atomic<std::size_t> used{0};
  std::vector<char> small(4096);
  PageWarmer warmer;
  warmer.start({{small.data(), small.size(), &used}}, std::size_t{4} << 20);
  warmer.stop();
  EXPECT_EQ(warmer.warmed_bytes(), 0u);
}

}  // namespace
}  // namespace primseg::detail
