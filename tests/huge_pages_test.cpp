#include "huge_pages.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace primseg::detail {
namespace {

TEST(HugePages, ReserveAndResizeKeepTheElementsAndMakeRoom) {
  std::vector<std::uint64_t> empty;
  reserve_huge(empty, 1u << 20);
  EXPECT_GE(empty.capacity(), 1u << 20);
  EXPECT_TRUE(empty.empty());

  std::vector<std::uint64_t> values = {3, 1, 4, 1, 5};
  reserve_huge(values, 1u << 20);
  EXPECT_GE(values.capacity(), 1u << 20);
  EXPECT_EQ(values, (std::vector<std::uint64_t>{3, 1, 4, 1, 5}));
  const std::uint64_t* data = values.data();
  reserve_huge(values, 10);  // already has room: the storage stays
  EXPECT_EQ(values.data(), data);

  std::vector<std::uint32_t> zeros;
  resize_huge(zeros, 3u << 20);
  ASSERT_EQ(zeros.size(), 3u << 20);
  EXPECT_TRUE(std::all_of(zeros.begin(), zeros.end(), [](std::uint32_t z) { return z == 0; }));

  std::vector<std::uint64_t> filled = {2, 7};
  reserve_huge_to_fill(filled, 1u << 20);
  EXPECT_GE(filled.capacity(), 1u << 20);
  EXPECT_EQ(filled, (std::vector<std::uint64_t>{2, 7}));
}

#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
// Faulting in makes every page of the range resident, from the page that holds its first byte to
// the one that holds its last, and nothing past them; what the pages held is kept.
TEST(HugePages, PopulatingMakesExactlyTheRangesPagesResidentAndKeepsTheirContents) {
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  constexpr std::size_t kPages = 16;
  void* block =
      mmap(nullptr, kPages * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(block, MAP_FAILED);
  auto* bytes = static_cast<char*>(block);
  bytes[page + 5] = 42;  // page 1 already resident, with a value
  auto resident = [&](std::size_t index) {
    unsigned char flag = 0;
    return mincore(bytes + index * page, page, &flag) == 0 && (flag & 1) != 0;
  };
  // From the middle of page 1 to the middle of page 9.
  ASSERT_TRUE(populate_pages(bytes + page + 100, 8 * page));
  for (std::size_t i = 0; i < kPages; ++i) EXPECT_EQ(resident(i), i >= 1 && i <= 9) << "page " << i;
  EXPECT_EQ(bytes[page + 5], 42);
  EXPECT_TRUE(std::all_of(bytes + 2 * page, bytes + 10 * page, [](char c) { return c == 0; }));
  EXPECT_TRUE(populate_pages(bytes, 0));  // nothing to do
  munmap(block, kPages * page);
}
#endif

#if defined(__linux__) && defined(MADV_DONTNEED)
// Releasing gives back the whole 2 MB blocks inside the range (they read zeros and are no longer
// resident) and keeps every byte outside them.
TEST(HugePages, ReleasingGivesBackTheAlignedInsideOfARangeOnly) {
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  constexpr std::size_t kHuge = std::size_t{2} << 20;
  void* block =
      mmap(nullptr, 4 * kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(block, MAP_FAILED);
  auto* bytes = static_cast<char*>(block);
  std::fill(bytes, bytes + 4 * kHuge, char{7});
  const auto base = reinterpret_cast<std::uintptr_t>(block);
  const std::size_t aligned = ((base + kHuge - 1) & ~(kHuge - 1)) - base;  // offset in block
  auto resident = [&](std::size_t offset) {
    unsigned char flag = 0;
    return mincore(bytes + offset / page * page, page, &flag) == 0 && (flag & 1) != 0;
  };
  // From 100 bytes before an aligned address to 100 bytes after the next one.
  release_pages(bytes + aligned - 100, kHuge + 200);
  EXPECT_FALSE(resident(aligned));
  EXPECT_FALSE(resident(aligned + kHuge - 1));
  EXPECT_TRUE(std::all_of(bytes + aligned, bytes + aligned + kHuge, [](char c) { return c == 0; }));
  EXPECT_TRUE(std::all_of(bytes, bytes + aligned, [](char c) { return c == 7; }));
  EXPECT_TRUE(
      std::all_of(bytes + aligned + kHuge, bytes + 4 * kHuge, [](char c) { return c == 7; }));
  // A range with no whole block inside: nothing is released.
  release_pages(bytes + aligned + kHuge + 1, kHuge);
  EXPECT_TRUE(
      std::all_of(bytes + aligned + kHuge, bytes + 4 * kHuge, [](char c) { return c == 7; }));
  munmap(block, 4 * kHuge);
}
#endif

#if defined(__linux__) && defined(MADV_HUGEPAGE)
// The VmFlags of the mapping that holds `address`, from /proc/self/smaps.
std::string vm_flags_at(const void* address) {
  const auto a = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  bool inside = false;
  for (std::string line; std::getline(smaps, line);) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-' &&
        line.find(':') > line.find(' ')) {
      inside = begin <= a && a < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return "";
}

// The advice reaches the 2 MB-aligned inside of a range and nothing outside it.
TEST(HugePages, TheAlignedInsideOfARangeIsAdvised) {
  if (!std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled"))
    GTEST_SKIP() << "no transparent huge pages in this kernel";
  constexpr std::size_t kHuge = std::size_t{2} << 20;
  void* block =
      mmap(nullptr, 4 * kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(block, MAP_FAILED);
  const auto base = reinterpret_cast<std::uintptr_t>(block);
  const std::uintptr_t aligned = (base + kHuge - 1) & ~(kHuge - 1);
  // A range that starts 100 bytes before an aligned address and ends 100 bytes after the next.
  auto* begin = reinterpret_cast<char*>(aligned - 100);  // NOLINT(performance-no-int-to-ptr)
  advise_huge_pages(begin, kHuge + 200);
  EXPECT_NE(vm_flags_at(begin + 100).find(" hg"), std::string::npos) << vm_flags_at(begin + 100);
  EXPECT_NE(vm_flags_at(begin + 100 + kHuge - 1).find(" hg"), std::string::npos);
  EXPECT_EQ(vm_flags_at(begin + 99).find(" hg"), std::string::npos) << vm_flags_at(begin + 99);
  EXPECT_EQ(vm_flags_at(begin + 100 + kHuge).find(" hg"), std::string::npos);
  munmap(block, 4 * kHuge);
}
#endif

}  // namespace
}  // namespace primseg::detail
