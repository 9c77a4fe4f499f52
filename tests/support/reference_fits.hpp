#pragma once
// The plane, cylinder and sphere fits as primseg computed them before the closed-form solvers and
// constant-time union views (issue 3): Eigen's iterative eigen-solver, Pratt's secular equation
// solved on g itself, and contractions of the union's whole moments about its centroid. Kept as
// the reference the new solvers must agree with (costs within 1e-9 relative above round-off).

#include <array>

#include "primseg/cluster_stats.hpp"
#include "primseg/hierarchy.hpp"

namespace primseg::testing {

struct ReferenceFit {
  bool valid = false;
  double error = 0;  // zero-snapped as the engine does
  double cost = 0;   // error × the type's penalty
  double normal_alignment = 1;
};

struct ReferenceModel {
  PrimitiveType type = PrimitiveType::Plane;
  double cost = 0;
  /// Per type (indexed by PrimitiveType; only plane, cylinder and sphere are fitted).
  std::array<ReferenceFit, kPrimitiveTypeCount> fits;
};

/// The model of a cluster with the previous solvers and the engine's selection rule, for
/// options whose primitives are among plane, cylinder and sphere. `centred`: statistics about the
/// centroid.
ReferenceModel reference_model(const ClusterStats& centred, const HierarchyOptions& options);

}  // namespace primseg::testing
