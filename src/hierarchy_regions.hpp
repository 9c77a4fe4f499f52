#pragma once
// The first phase of HierarchyOptions::regions (approximate, for speed): the mesh cut into
// regions, each merged by itself on its own thread, their merges interleaved by cost.

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "primseg/dual_graph.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh.hpp"

namespace primseg::detail {

/// Each region's merges stop when it has this many times fewer clusters than faces: the levels
/// from F / kRegionFacesPerCluster clusters up are made by the exact greedy order over the whole
/// mesh, from the regions' clusters.
inline constexpr std::uint32_t kRegionFacesPerCluster = 32;
/// Regions have at least this many faces: a smaller mesh is merged as one region.
inline constexpr std::uint32_t kMinRegionFaces = 4096;

/// The faces of `count` regions of nearly equal face counts: recursive cuts at the median of the
/// faces' first triangles' centroids along the longest side of their bounding box. Each region
/// lists its faces in increasing order; together they are every face once.
std::vector<std::vector<std::uint32_t>> split_into_regions(const Mesh& mesh, unsigned count);

/// The mesh made of the given faces of `mesh` (in that order), their vertices numbered by first
/// use; `first` is first_triangles(mesh) (face_triangles.hpp), made once for every region.
Mesh region_mesh(const Mesh& mesh, const std::vector<std::uint32_t>& first,
                 const std::vector<std::uint32_t>& faces);

/// Merges each of options.regions regions of the mesh by itself (on options.threads threads,
/// one region per thread), until it has a kRegionFacesPerCluster-th of its faces as clusters,
/// and appends their merges to `merges` in the mesh's node ids (face f is leaf f, merge i makes
/// node F + i), interleaved in order of cost, costs and errors in the mesh's working frame.
/// Weights are left as the regions computed them (near the cuts, uniform weights count other
/// valences). `then` runs on the first thread left without a region (the regions rarely take
/// equal times). Returns the candidate evaluations the regions made; 0, with nothing appended,
/// when the mesh has too few faces for two regions of kMinRegionFaces (`then` not called) or a
/// region fails a check of its own (InvalidInputError: `then` may have run).
std::uint64_t region_merges(const Mesh& mesh, const HierarchyOptions& options,
                            std::vector<Merge>& merges, const std::function<void()>& then);

/// Whether every merge of `merges` (the first merges of a tree of the graph's faces) joins two
/// clusters that a dual edge of `graph` links. A region links the triangles on a non-manifold
/// edge in a chain of its own, which may join two faces the whole mesh's chain does not.
/// O(E log F).
bool merges_join_linked_clusters(const DualGraph& graph, std::span<const Merge> merges);

}  // namespace primseg::detail
