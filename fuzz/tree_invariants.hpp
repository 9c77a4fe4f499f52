// Invariants of a tree and of its cuts that every engine fuzzer checks; `fail` aborts, which
// libFuzzer reports as a finding.

#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"

namespace primseg::fuzz {

[[noreturn]] inline void fail(const char* what, double a = 0, double b = 0) {
  std::fprintf(stderr, "invariant broken: %s (%.17g, %.17g)\n", what, a, b);
  std::abort();
}

struct DisjointSets {
  std::vector<std::uint32_t> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
};

inline void check_tree(const Hierarchy& hierarchy) {
  const std::uint32_t faces = hierarchy.face_count();
  if (hierarchy.merges().size() != faces - 1)
    fail("merge count", unsigned(hierarchy.merges().size()), faces);
  std::vector<std::uint32_t> parent_count(hierarchy.node_count(), 0);
  for (std::uint32_t i = 0; i < hierarchy.merges().size(); ++i) {
    const Merge& merge = hierarchy.merges()[i];
    const std::uint32_t node = faces + i;
    if (!(merge.first < merge.second) || merge.second >= node)
      fail("children order", merge.first, node);
    ++parent_count[merge.first];
    ++parent_count[merge.second];
    if (merge.face_count != hierarchy.face_count(merge.first) + hierarchy.face_count(merge.second))
      fail("face count of a merge", node);
    if (hierarchy.parents()[merge.first] != node || hierarchy.parents()[merge.second] != node)
      fail("parents", node);
  }
  // The checks of a tree given by its parts (a tree file) accept every tree the builder makes.
  try {
    const Hierarchy copy(hierarchy.shared_mesh(), hierarchy.options(),
                         std::vector<Merge>(hierarchy.merges().begin(), hierarchy.merges().end()));
  } catch (const InvalidInputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    fail("the tree's parts are refused");
  }
  for (std::uint32_t node = 0; node + 1 < hierarchy.node_count(); ++node)
    if (parent_count[node] != 1) fail("node without exactly one parent", node, parent_count[node]);
  if (parent_count.back() != 0) fail("root has a parent");
}

inline void check_cut(const Hierarchy& hierarchy, const Segmentation& segmentation) {
  const std::uint32_t faces = hierarchy.face_count();
  const std::uint32_t clusters = segmentation.cluster_count();
  if (segmentation.labels.size() != faces) fail("label count");
  std::vector<std::uint32_t> size(clusters, 0);
  for (std::uint32_t f = 0; f < faces; ++f) {
    if (segmentation.labels[f] >= clusters) fail("label out of range", f, segmentation.labels[f]);
    ++size[segmentation.labels[f]];
  }
  for (std::uint32_t c = 0; c < clusters; ++c)
    if (size[c] == 0) fail("empty cluster", c);
  // Connected: union faces across dual edges inside one cluster; one set per cluster.
  DisjointSets sets(faces);
  for (const DualEdge& edge : hierarchy.graph().edges())
    if (segmentation.labels[edge.first] == segmentation.labels[edge.second])
      sets.parent[sets.find(edge.first)] = sets.find(edge.second);
  std::vector<std::uint32_t> root_of_cluster(clusters, UINT32_MAX);
  for (std::uint32_t f = 0; f < faces; ++f) {
    std::uint32_t& root = root_of_cluster[segmentation.labels[f]];
    if (root == UINT32_MAX) root = sets.find(f);
    if (root != sets.find(f)) fail("cluster not connected", segmentation.labels[f], f);
  }
}

}  // namespace primseg::fuzz
