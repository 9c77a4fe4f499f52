#pragma once
// Transparent huge pages for the large arrays of a build.
//
// A mesh of a million faces touches about 200,000 pages of 4 KB, and each first touch is a page
// fault: on a virtual machine about 7 µs each, 13% of bunny00's build. Where the kernel grants
// transparent huge pages on request (/sys/kernel/mm/transparent_hugepage/enabled = madvise; with
// `always` it does anyway, with `never` not at all), an array asked for with
// madvise(MADV_HUGEPAGE) before its first touch takes one fault per 2 MB instead of 512, and
// fewer TLB misses when read at random. The advice changes no value: only where the memory
// comes from. Pages of arrays filled at once are faulted in by one call (populate_pages), which
// halves the cost of those below 2 MB.

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace primseg::detail {

#if defined(__linux__)
/// The 2 MB-aligned part of [data, data + bytes), as madvise takes it: its start and length (0
/// when there is none).
inline std::pair<void*, std::size_t> whole_huge_pages(const void* data, std::size_t bytes) {
  constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t last = (begin + bytes) & ~(kHugePage - 1);
  void* start = reinterpret_cast<void*>(first);  // NOLINT(performance-no-int-to-ptr)
  return {start, last > first ? last - first : 0};
}
#endif

/// Advises the kernel to back the 2 MB-aligned part of [data, data + bytes) with huge pages
/// (Linux; elsewhere nothing). Only pages not yet touched are affected. Errors are ignored: the
/// advice is an optimisation (kernels without THP refuse it).
inline void advise_huge_pages(const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  const auto [start, length] = whole_huge_pages(data, bytes);
  if (length > 0) madvise(start, length, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

/// Gives the 2 MB-aligned part of [data, data + bytes) back to the system (Linux: madvise
/// MADV_DONTNEED; elsewhere nothing), for the consumed part of a large array of trivially
/// destructible elements that will not be read again: read, it would hold zeros. The array's own
/// storage only, and its first and last partial huge pages stay, so no huge page is split.
inline void release_pages(const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_DONTNEED)
  const auto [start, length] = whole_huge_pages(data, bytes);
  if (length > 0) madvise(start, length, MADV_DONTNEED);
#else
  (void)data;
  (void)bytes;
#endif
}

/// Faults the pages of [data, data + bytes) in with one call, as a write to each would (their
/// contents unchanged), but at half the cost per page on a virtual machine: about 5 µs against
/// 10 µs for a page of 4 KB first touched by a write. Whether the kernel did: Linux 5.14 and
/// later (madvise MADV_POPULATE_WRITE); elsewhere, or when refused, nothing is done and the
/// pages fault on first use as before.
inline bool populate_pages(const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
  constexpr std::uintptr_t kPage = 4096;  // the smallest page: madvise wants a multiple
  if (bytes == 0) return true;
  const auto begin = reinterpret_cast<std::uintptr_t>(data) & ~(kPage - 1);
  const std::uintptr_t end = reinterpret_cast<std::uintptr_t>(data) + bytes;
  void* start = reinterpret_cast<void*>(begin);  // NOLINT(performance-no-int-to-ptr)
  return madvise(start, end - begin, MADV_POPULATE_WRITE) == 0;
#else
  (void)data;
  (void)bytes;
  return false;
#endif
}

/// v.reserve(n), the storage past v's elements advised for huge pages (all of it for an empty
/// container, before anything is written to it). `v`: a std::vector, or a std::string that a file
/// is assembled in.
template <typename Contiguous>
void reserve_huge(Contiguous& v, std::size_t n) {
  if (n <= v.capacity()) return;
  v.reserve(n);
  advise_huge_pages(v.data() + v.size(), (v.capacity() - v.size()) * sizeof(*v.data()));
}

/// reserve_huge(v, n) for a v that is about to be filled to n elements: the storage past its
/// elements is also faulted in at once. Only for sizes known to be used (not a count read from a
/// file's header, which may lie): the pages are committed now.
template <typename Contiguous>
void reserve_huge_to_fill(Contiguous& v, std::size_t n) {
  if (n <= v.capacity()) return;
  reserve_huge(v, n);
  populate_pages(v.data() + v.size(), (n - v.size()) * sizeof(*v.data()));
}

/// v.resize(n) for an empty v, its storage advised for huge pages and faulted in before it is
/// filled.
template <typename T>
void resize_huge(std::vector<T>& v, std::size_t n) {
  reserve_huge_to_fill(v, n);
  v.resize(n);
}

}  // namespace primseg::detail
