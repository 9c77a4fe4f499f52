#pragma once
/// @file no_index.hpp
/// The sentinel of the library's 32-bit index arrays: no vertex, face, cluster or node.

#include <cstdint>
#include <limits>

namespace primseg::detail {

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

}  // namespace primseg::detail
