#pragma once
// The faces of every tree node as one contiguous range: what reads a node's faces without a cut
// (describe_nodes, LevelRegularizer) walks.

#include <algorithm>
#include <cstdint>
#include <vector>

#include "primseg/hierarchy.hpp"

namespace primseg::detail {

/// The faces in the order of the tree's leaves (first child first): node n's faces are
/// faces[start[n], start[n] + face_count(n)). Shapes (2F − 1) and (F). O(F).
struct LeafOrder {
  std::vector<std::uint32_t> start;
  std::vector<std::uint32_t> faces;

  explicit LeafOrder(const Hierarchy& hierarchy)
      : start(hierarchy.node_count(), 0), faces(hierarchy.face_count()) {
    const std::uint32_t f = hierarchy.face_count();
    const auto merges = hierarchy.merges();
    for (std::uint32_t node = hierarchy.node_count(); node-- > f;) {
      const Merge& merge = merges[node - f];
      start[merge.first] = start[node];
      start[merge.second] = start[node] + hierarchy.face_count(merge.first);
    }
    for (std::uint32_t face = 0; face < f; ++face) faces[start[face]] = face;
  }

  /// Node n's faces in ascending order (their triangles are then in ascending order, as a cut's),
  /// into `out`.
  void ascending_faces(const Hierarchy& hierarchy, std::uint32_t node,
                       std::vector<std::uint32_t>& out) const {
    out.assign(faces.begin() + start[node],
               faces.begin() + start[node] + hierarchy.face_count(node));
    std::sort(out.begin(), out.end());
  }
};

}  // namespace primseg::detail
