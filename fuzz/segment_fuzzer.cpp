// libFuzzer target for the engine: decodes a small mesh from the input (vertices on a coarse
// integer grid, so that coplanar, cocircular, degenerate and duplicate configurations are
// common), builds its hierarchy and checks the invariants a user relies on:
// - the tree is a full binary tree over the F faces (F − 1 merges, children created before their
//   parent, every node but the root has exactly one parent);
// - every cut, by count for every K in 1..F and by tolerance at a few levels, labels each face
//   with a cluster in 0..K'-1, every cluster is non-empty and edge-connected in the dual graph.
//
// Input layout: byte 0 = vertex count − 3 (mod 29), then 3 bytes per vertex (a coordinate in
// -8..7 from each byte), then 3 bytes per triangle (vertex indices mod the vertex count), at most
// 48 triangles. Triangles that repeat a vertex are skipped.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numeric>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"

namespace {

[[noreturn]] void fail(const char* what, unsigned a = 0, unsigned b = 0) {
  std::fprintf(stderr, "invariant broken: %s (%u, %u)\n", what, a, b);
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

void check_tree(const primseg::Hierarchy& hierarchy) {
  const std::uint32_t faces = hierarchy.face_count();
  if (hierarchy.merges().size() != faces - 1)
    fail("merge count", unsigned(hierarchy.merges().size()), faces);
  std::vector<std::uint32_t> parent_count(hierarchy.node_count(), 0);
  for (std::uint32_t i = 0; i < hierarchy.merges().size(); ++i) {
    const primseg::Merge& merge = hierarchy.merges()[i];
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
  for (std::uint32_t node = 0; node + 1 < hierarchy.node_count(); ++node)
    if (parent_count[node] != 1) fail("node without exactly one parent", node, parent_count[node]);
  if (parent_count.back() != 0) fail("root has a parent");
}

void check_cut(const primseg::Hierarchy& hierarchy, const primseg::Segmentation& segmentation) {
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
  for (const primseg::DualEdge& edge : hierarchy.graph().edges())
    if (segmentation.labels[edge.first] == segmentation.labels[edge.second])
      sets.parent[sets.find(edge.first)] = sets.find(edge.second);
  std::vector<std::uint32_t> root_of_cluster(clusters, UINT32_MAX);
  for (std::uint32_t f = 0; f < faces; ++f) {
    std::uint32_t& root = root_of_cluster[segmentation.labels[f]];
    if (root == UINT32_MAX) root = sets.find(f);
    if (root != sets.find(f)) fail("cluster not connected", segmentation.labels[f], f);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::size_t vertex_count = 3 + data[0] % 29;
  if (size < 1 + 3 * vertex_count) return 0;
  std::vector<primseg::Vec3> positions(vertex_count);
  const std::uint8_t* in = data + 1;
  for (primseg::Vec3& p : positions)
    for (double& c : p) c = static_cast<double>(*in++ % 16) - 8.0;
  std::vector<primseg::Triangle> triangles;
  for (; in + 3 <= data + size && triangles.size() < 48; in += 3) {
    const primseg::Triangle t{static_cast<std::uint32_t>(in[0] % vertex_count),
                              static_cast<std::uint32_t>(in[1] % vertex_count),
                              static_cast<std::uint32_t>(in[2] % vertex_count)};
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) triangles.push_back(t);
  }
  if (triangles.empty()) return 0;

  auto mesh = std::make_shared<const primseg::Mesh>(
      primseg::Mesh::from_triangles(std::move(positions), std::move(triangles)));
  primseg::HierarchyOptions options;
  options.threads = 1;
  const primseg::Hierarchy hierarchy = primseg::build_hierarchy(mesh, options);
  check_tree(hierarchy);
  const std::uint32_t faces = hierarchy.face_count();
  for (std::uint32_t k = 1; k <= faces; ++k) {
    const primseg::Segmentation segmentation = primseg::cut_by_count(hierarchy, k);
    const std::uint32_t expected = std::max(k, hierarchy.component_count());
    if (segmentation.cluster_count() != expected)
      fail("cluster count of a cut", k, segmentation.cluster_count());
    check_cut(hierarchy, segmentation);
  }
  for (const double tolerance : {0.0, 1e-9, 0.01, 0.3, 1.0, 100.0})
    check_cut(hierarchy, primseg::cut_by_tolerance(hierarchy, tolerance));
  return 0;
}
