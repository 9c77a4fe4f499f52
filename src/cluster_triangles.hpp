#pragma once
// The triangles of each cluster of a labelling, for the code that walks a level cluster by
// cluster (describe_clusters(), regularize_clusters()).

#include <cstdint>
#include <span>
#include <vector>

#include "primseg/mesh.hpp"

namespace primseg::detail {

/// Each cluster's triangles in ascending order, as rows of a compressed array (a counting sort:
/// O(T + K)).
struct ClusterTriangles {
  std::vector<std::uint32_t> offsets;  ///< shape (K + 1)
  std::vector<std::uint32_t> triangles;

  /// `labels`: one per face of `mesh`, each below `clusters` (checked by the caller).
  ClusterTriangles(const Mesh& mesh, std::span<const std::uint32_t> labels, std::uint32_t clusters)
      : offsets(static_cast<std::size_t>(clusters) + 1, 0), triangles(mesh.triangle_count()) {
    for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t)
      ++offsets[labels[mesh.face_of_triangle[t]] + 1];
    for (std::uint32_t c = 0; c < clusters; ++c) offsets[c + 1] += offsets[c];
    std::vector<std::uint32_t> next(offsets.begin(), offsets.end() - 1);
    for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t)
      triangles[next[labels[mesh.face_of_triangle[t]]]++] = t;
  }

  std::span<const std::uint32_t> of(std::size_t cluster) const {
    return std::span<const std::uint32_t>(triangles).subspan(
        offsets[cluster], offsets[cluster + 1] - offsets[cluster]);
  }
};

}  // namespace primseg::detail
