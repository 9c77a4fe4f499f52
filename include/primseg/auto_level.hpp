#pragma once
/// @file auto_level.hpp
/// The error curve of a hierarchy and the automatic choice of its most significant level(s).
///
/// Cutting the tree by count (cut_by_count) gives, for every K, a level whose total fitting
/// error E(K) only grows as K falls. On objects made of a few regular surfaces the curve stays
/// near the noise level while merges join pieces of one surface, and jumps when a merge first
/// joins two different surfaces: the level just before a large jump is significant.

#include <cstdint>
#include <vector>

#include "primseg/hierarchy.hpp"

namespace primseg {

/// One point of the error curve.
struct ErrorCurvePoint {
  std::uint32_t clusters = 0;  ///< K
  /// sqrt(Σ over the K clusters of their L2 error / Σ of their weights): the RMS distance
  /// estimate of the whole level (input units).
  double rms = 0;
};

/// The error curve for every K from the number of components C up to the face count F, in
/// increasing K: shape (F − C + 1). O(F).
std::vector<ErrorCurvePoint> error_curve(const Hierarchy& hierarchy);

/// Options of choose_levels().
struct AutoLevelOptions {
  /// RMS values below this fraction of the bounding-box diagonal count as this value: round-off
  /// of exact fits must not make a jump from 1e-17 to 1e-15 look significant.
  double rms_floor = 1e-6;
  /// A level is chosen only if its score is at least this; otherwise (no jump stands out) the
  /// answer is one cluster per component.
  double min_score = 2.0;
  /// Candidates reported, best first (the chosen level is the first).
  std::uint32_t max_candidates = 5;
};

/// A candidate level and how strongly the curve singles it out.
struct LevelCandidate {
  std::uint32_t clusters = 0;  ///< K
  double rms = 0;              ///< rms of the curve at K (input units)
  /// Significance of K, >= 1: how much the curve jumps when going from K to K − 1 clusters,
  /// relative to how much it grew from K + 1 to K, each as a ratio of floored RMS values (so a
  /// smooth curve scores about 1 everywhere). One cluster per component scores min_score.
  double score = 0;
};

/// The chosen level and the runners-up.
struct AutoLevel {
  std::uint32_t clusters = 0;              ///< the chosen K
  std::vector<LevelCandidate> candidates;  ///< best first; candidates[0].clusters == clusters
};

/// Picks the most significant level of the hierarchy from its error curve. Deterministic;
/// O(F log F). Throws InvalidInputError for options out of range (negative or non-finite floor,
/// min_score below 1, no candidate asked for).
AutoLevel choose_level(const Hierarchy& hierarchy, const AutoLevelOptions& options = {});

}  // namespace primseg
