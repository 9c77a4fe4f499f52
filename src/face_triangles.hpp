#pragma once
// Where each face's triangles start in a mesh's triangle list.

#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

#include "huge_pages.hpp"
#include "primseg/mesh.hpp"

namespace primseg::detail {

/// The first triangle of each face, shape (F + 1): face f has triangles [first[f], first[f + 1])
/// (face_of_triangle is non-decreasing).
inline std::vector<std::uint32_t> first_triangles(const Mesh& mesh) {
  std::vector<std::uint32_t> first;
  resize_huge(first, std::size_t{mesh.face_count()} + 1);
  for (const std::uint32_t face : mesh.face_of_triangle) ++first[face + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  return first;
}

}  // namespace primseg::detail
