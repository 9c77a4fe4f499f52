#include "orientation_repair.hpp"

namespace primseg {

std::uint32_t revert_inverted_triangles(std::span<Vec3> positions, std::span<const Vec3> safe,
                                        const std::vector<Triangle>& triangles,
                                        std::span<const Vec3> reference_normals) {
  using detail::to_eigen;
  std::vector<char> reverted(positions.size(), 0);
  std::uint32_t count = 0;
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      const Triangle& corners = triangles[t];
      if (!turned_over(to_eigen(positions[corners[0]]), to_eigen(positions[corners[1]]),
                       to_eigen(positions[corners[2]]), reference_normals[t]))
        continue;
      for (const std::uint32_t v : triangles[t]) {
        if (reverted[v]) continue;
        reverted[v] = 1;
        positions[v] = safe[v];
        ++count;
        changed = true;
      }
    }
  }
  return count;
}

}  // namespace primseg
