#pragma once
// Tree nodes read without a cut's per-face labels, in one place: which nodes a report can
// describe, the clusters of a level, and the faces of every node as one contiguous range
// (cut_by_count, describe_nodes, LevelRegularizer).

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"

namespace primseg::detail {

/// Throws InvalidInputError, its message starting with `who`, unless `node` is a node of the tree
/// that a cut can hold: not a trailing merge, which joins components and has no fit.
inline void check_cluster_node(const Hierarchy& hierarchy, std::uint32_t node, const char* who) {
  const std::uint32_t f = hierarchy.face_count();
  if (node >= hierarchy.node_count() || (node >= f && hierarchy.merges()[node - f].trailing))
    throw InvalidInputError(std::string(who) + ": " + std::to_string(node) +
                            " is not a node of the tree, or joins components");
}

/// The clusters of cut_by_count()'s level of `clusters` clusters (the component count at least),
/// unordered: the nodes of the applied merges and the leaves whose parent is not applied, that is
/// the children of the merges not applied (the root alone when all are). O(K). Throws
/// InvalidInputError unless 1 <= clusters <= F.
inline std::vector<std::uint32_t> level_nodes(const Hierarchy& hierarchy, std::uint32_t clusters) {
  const std::uint32_t f = hierarchy.face_count();
  if (clusters < 1 || clusters > f)
    throw InvalidInputError("the number of clusters must be between 1 and " + std::to_string(f) +
                            ", not " + std::to_string(clusters));
  const auto merges = hierarchy.merges();
  const std::uint32_t real = f - hierarchy.component_count();
  const std::uint32_t applied = std::min(real, f - clusters);
  if (applied == merges.size()) return {hierarchy.node_count() - 1};
  std::vector<std::uint32_t> nodes;
  for (std::size_t i = applied; i < merges.size(); ++i)
    for (const std::uint32_t child : {merges[i].first, merges[i].second})
      if (child < f + applied) nodes.push_back(child);
  return nodes;
}

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
