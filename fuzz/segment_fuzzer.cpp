// libFuzzer target for the engine: decodes a small mesh from the input (vertices on a coarse
// integer grid, so that coplanar, cocircular, degenerate and duplicate configurations are
// common), builds its hierarchy and checks the invariants a user relies on:
// - the tree is a full binary tree over the F faces (F − 1 merges, children created before their
//   parent, every node but the root has exactly one parent), and Hierarchy's constructor from
//   parts, which checks tree files, accepts it (tree_invariants.hpp);
// - every cut, by count for every K in 1..F and by tolerance at a few levels, labels each face
//   with a cluster in 0..K'-1, every cluster is non-empty and edge-connected in the dual graph;
// - the approximate merge order (merge_batch_tolerance) builds such a tree too;
// - with the types whose costs give lower bounds (planes; planes and spheres), lazy evaluation
//   builds the eager order's tree, byte for byte: a bound that fails to hold on these inputs
//   (duplicate, degenerate and coplanar faces) would reorder the merges.
//
// Input layout: grid_mesh.hpp.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "grid_mesh.hpp"
#include "primseg/cut.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/primitive.hpp"
#include "primseg/tree_io.hpp"
#include "tree_invariants.hpp"

namespace {

void check_lazy_is_eager(const std::shared_ptr<const primseg::Mesh>& mesh,
                         std::vector<primseg::PrimitiveType> types) {
  primseg::HierarchyOptions options;
  options.threads = 1;
  options.primitives = std::move(types);
  const std::string lazy = primseg::serialize_tree(primseg::build_hierarchy(mesh, options));
  options.evaluation = primseg::CandidateEvaluation::Eager;
  if (primseg::serialize_tree(primseg::build_hierarchy(mesh, options)) != lazy)
    primseg::fuzz::fail("the lazy order's tree differs from the eager one");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::optional<primseg::Mesh> decoded = primseg::fuzz::decode_grid_mesh(data, size);
  if (!decoded) return 0;
  auto mesh = std::make_shared<const primseg::Mesh>(std::move(*decoded));
  primseg::HierarchyOptions options;
  options.threads = 1;
  const primseg::Hierarchy hierarchy = primseg::build_hierarchy(mesh, options);
  primseg::fuzz::check_tree(hierarchy);
  const std::uint32_t faces = hierarchy.face_count();
  for (std::uint32_t k = 1; k <= faces; ++k) {
    const primseg::Segmentation segmentation = primseg::cut_by_count(hierarchy, k);
    const std::uint32_t expected = std::max(k, hierarchy.component_count());
    if (segmentation.cluster_count() != expected)
      primseg::fuzz::fail("cluster count of a cut", k, segmentation.cluster_count());
    primseg::fuzz::check_cut(hierarchy, segmentation);
  }
  for (const double tolerance : {0.0, 1e-9, 0.01, 0.3, 1.0, 100.0})
    primseg::fuzz::check_cut(hierarchy, primseg::cut_by_tolerance(hierarchy, tolerance));
  // The approximate merge order (large batches) builds a full tree over the same faces too.
  options.merge_batch_tolerance = 0.5;
  const primseg::Hierarchy batched = primseg::build_hierarchy(mesh, options);
  primseg::fuzz::check_tree(batched);
  if (batched.merges().size() != hierarchy.merges().size())
    primseg::fuzz::fail("merges of the batched order", double(hierarchy.merges().size()),
                        double(batched.merges().size()));
  check_lazy_is_eager(mesh, {primseg::PrimitiveType::Plane});
  check_lazy_is_eager(mesh, {primseg::PrimitiveType::Plane, primseg::PrimitiveType::Sphere});
  return 0;
}
