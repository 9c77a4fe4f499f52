// Dual-graph neighbours of every face in compressed rows, for walks over clusters (boundary
// refinement's connectivity, the tree check's adjacency of merged clusters).

#pragma once

#include <cstdint>
#include <numeric>
#include <vector>

#include "primseg/dual_graph.hpp"

namespace primseg::detail {

struct FaceAdjacency {
  /// Face f's neighbours are neighbour[offset[f]] .. neighbour[offset[f + 1] - 1], shape (F + 1).
  std::vector<std::uint32_t> offset, neighbour;

  explicit FaceAdjacency(const DualGraph& graph) : offset(graph.face_count() + 1, 0) {
    for (const DualEdge& e : graph.edges()) ++offset[e.first + 1], ++offset[e.second + 1];
    std::partial_sum(offset.begin(), offset.end(), offset.begin());
    neighbour.resize(offset.back());
    std::vector<std::uint32_t> next(offset.begin(), offset.end() - 1);
    for (const DualEdge& e : graph.edges()) {
      neighbour[next[e.first]++] = e.second;
      neighbour[next[e.second]++] = e.first;
    }
  }
};

}  // namespace primseg::detail
