#pragma once
// Choosing a cluster's primitive type: the honest-model rule shared by merges and leaves.

#include <functional>

#include "primseg/hierarchy.hpp"
#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg::detail {

struct SelectedModel {
  PrimitiveFit fit;  // working frame; fit.error already zero-snapped
  double cost = 0;   // penalised error: the merge priority
  /// A lower bound of the cost of every cluster containing this one (see
  /// PrimitiveFit::superset_error_bound), shrunk by a margin
  /// far above round-off so that it holds for the computed costs too. 0 under Eager.
  double superset_cost_bound = 0;
};

/// Exact Σ w d² of a working-frame primitive over a cluster's corners.
using ExactError = std::function<double(const Primitive&)>;

/// The rule: every enabled type with enough triangles is fitted; invalid fits drop out; errors at
/// most zero_cost_tolerance × Σ w |x − c|² snap to 0; the smallest error × penalty wins; among
/// exact fits (cost 0) the best normal agreement (PrimitiveFit::normal_alignment) wins, other
/// ties go to the lower type. If no enabled type is valid the cluster is reported as a plane (the
/// limit of every curved type as its radius grows), whether or not planes are enabled.
class ModelSelector {
 public:
  explicit ModelSelector(const HierarchyOptions& options);
  /// Highest moment degree the fits of a cluster of this many triangles use: 2 when only a plane
  /// can be fitted (too few triangles for any curved type), else 4.
  int moment_degree(std::uint32_t triangle_count) const {
    return triangle_count >= min_curved_triangles_ ? 4 : 2;
  }
  /// Highest moment degree a stored cluster needs: 4 when a curved type is enabled (the cluster
  /// may join a union that type fits), else 2 (the plane reads the second moment only).
  int stored_moment_degree() const { return min_curved_triangles_ == UINT32_MAX ? 2 : 4; }
  /// Whether some enabled type reads ClusterStats::samples (DualGraph::face_stats must fill them).
  bool needs_samples() const { return needs_samples_; }
  /// Whether every enabled type's fit is a closed form (PrimitiveFitter::closed_form).
  bool closed_form() const { return closed_form_; }
  /// The model of a cluster or of the union of two (a merge candidate). `exact`: if given,
  /// replaces each fit's error by the exact one.
  SelectedModel select(const ClusterView& cluster, const ExactError* exact = nullptr) const;
  /// What select(cluster) chose, given the type it chose: only that type is fitted (its fit is
  /// the same whatever select() had to beat), with the same error and cost.
  SelectedModel refit(const ClusterView& cluster, PrimitiveType chosen) const;
  /// `centred`: statistics with moments about the cluster's centroid.
  SelectedModel select(const ClusterStats& centred, const ExactError* exact = nullptr) const {
    return select(ClusterView(centred), exact);
  }

 private:
  // Makes the fit's error exact if asked, and zero-snapped; returns its cost.
  double finish(PrimitiveFit& fit, double zero_level, const ExactError* exact) const;

  std::vector<const PrimitiveFitter*> fitters_;  // ascending type
  std::uint32_t min_curved_triangles_ = UINT32_MAX;
  bool needs_samples_ = false;
  bool closed_form_ = true;
  HierarchyOptions options_;
};

}  // namespace primseg::detail
