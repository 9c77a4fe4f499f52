#include "orientation_repair.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "eigen_conversions.hpp"

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
      std::array<Eigen::Vector3d, 3> corner;
      for (int k = 0; k < 3; ++k) corner[k] = to_eigen(positions[triangles[t][k]]);
      const Eigen::Vector3d normal = (corner[1] - corner[0]).cross(corner[2] - corner[0]);
      if (normal.dot(to_eigen(reference_normals[t])) >= 0) continue;
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
