#include "edge_sides.hpp"

#include <algorithm>

namespace primseg::detail {

std::vector<std::uint32_t> triangle_labels(const Mesh& mesh,
                                           std::span<const std::uint32_t> face_labels) {
  std::vector<std::uint32_t> labels(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    labels[t] = face_labels[mesh.face_of_triangle[t]];
  return labels;
}

std::vector<EdgeSide> edge_sides(const Mesh& mesh, std::span<const std::uint32_t> triangle_labels) {
  std::vector<EdgeSide> sides;
  sides.reserve(3 * mesh.triangles.size());
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = tri[e], b = tri[(e + 1) % 3];
      if (a != b) sides.push_back({std::min(a, b), std::max(a, b), triangle_labels[t], t});
    }
  }
  std::sort(sides.begin(), sides.end());
  return sides;
}

std::size_t edge_end(std::span<const EdgeSide> sides, std::size_t begin) {
  std::size_t end = begin + 1;
  while (end < sides.size() && sides[end].low == sides[begin].low &&
         sides[end].high == sides[begin].high)
    ++end;
  return end;
}

}  // namespace primseg::detail
