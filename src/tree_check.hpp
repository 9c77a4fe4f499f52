// What build_hierarchy guarantees of a tree, checked for a tree given by its parts (a tree file,
// or a caller's merges), so that cuts, reports and every tool can rely on it.

#pragma once

#include <span>

#include "primseg/dual_graph.hpp"
#include "primseg/hierarchy.hpp"

namespace primseg::detail {

/// Throws InvalidInputError naming the first merge that breaks a rule: children given as
/// first < second; each merge's face count the sum of its children's, and its weight the sum of
/// its faces' corner weights (within 1e-9 relative); cost, error and weight finite and
/// non-negative, the cost at most 1e300 and the RMS error sqrt(error / weight) at most 1e30
/// working units; a real merge's primitive of an enabled type with finite parameters
/// within 1e30 working units of the mesh, non-negative radii and a unit axis (within 1e-9; every
/// type but the sphere has one), and its children sharing a mesh edge (dual-graph neighbours); the
/// F − C real merges first, then C − 1 trailing ones. `merges` must already form a binary tree
/// (children before parents, each node used once). O(E log F) for E dual edges.
void check_tree_parts(const DualGraph& graph, const HierarchyOptions& options,
                      std::span<const Merge> merges);

}  // namespace primseg::detail
