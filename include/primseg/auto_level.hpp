#pragma once
/// @file auto_level.hpp
/// The error curve of a hierarchy and the automatic choice of its most significant level(s).
///
/// Cutting the tree by count (cut_by_count) gives, for every K, a level whose total fitting
/// error E(K) only grows as K falls. On objects made of a few regular surfaces the curve stays
/// near the noise level while merges join pieces of one surface, and jumps when a merge first
/// joins two different surfaces: the level just before a large jump is significant.

#include <cstdint>
#include <string_view>
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

/// Options of choose_level().
struct AutoLevelOptions {
  /// RMS values below this fraction of the bounding-box diagonal count as this value: on exact
  /// data the curve wavers at round-off and first-order-fit level (about 1e-6 of the diagonal),
  /// and such wavering must not look like a jump. 1e-4 stays well below the noise of scanned
  /// parts, and far below any error a reverse engineer would call a different surface.
  double rms_floor = 1e-4;
  /// The same floor for the knee (AutoLevelRule::Knee), a fraction of the diagonal too: the
  /// round-off and first-order-fit level only. A curve that falls gently into rms_floor within the
  /// knee's search range (a finely tessellated part whose clusters fit a little better as they
  /// shrink, down to a few dozen triangles each) would be flat from there on, and the L-method
  /// would take that made-up bend for the knee: fandisk_large.off of libcgal-demo (31,682 faces)
  /// got 1,272 clusters instead of its 25 surfaces.
  double knee_rms_floor = 1e-6;
  /// A jump is significant when its score is at least this.
  double min_score = 2.0;
  /// Candidates reported besides the chosen level (the best-scored ones).
  std::uint32_t max_candidates = 5;
  /// When no jump is significant, choose the knee of the curve (AutoLevelRule::Knee) rather
  /// than one cluster per component.
  bool knee_fallback = true;
  /// Also count a jump of the cluster the next merge makes (LevelCandidate::merge_score), on a
  /// level at the noise plateau: where a small region (a chamfer, a fillet, a dome) joins its
  /// neighbour, the RMS of the whole level rises by far less than min_score even when the merged
  /// cluster fits several times worse than the level. On the generated shapes (9 seeds, three
  /// tessellations) the chosen K is the true count in 98% of cases with cones and tori enabled,
  /// 88% without this rule; 95% and 92% with the default types. false: the level's score alone.
  bool cluster_jumps = true;
};

/// Which rule chose the level.
enum class AutoLevelRule {
  /// The finest K whose score reaches min_score: a jump of the curve. With
  /// AutoLevelOptions::cluster_jumps, also a K whose next merge makes a cluster at least
  /// min_score times the level's RMS (merge_score), while the level's RMS rises by at least 25%
  /// and K lies on the curve's noise plateau: rms(K) at most 1.15 times rms(min(2K, F)), so that
  /// twice the clusters would fit hardly better (noise, not detail, is what is left). A merged
  /// cluster within 0.2% of the bounding-box diagonal (twice 0.1%) is never such a jump: that
  /// small a misfit of an exact surface is tessellation, not a second surface.
  Jump,
  /// No significant jump: the knee of log rms against K (rms floored at knee_rms_floor), by the
  /// L-method (Salvador and Chan 2004): two least-squares lines, one through the coarse levels and
  /// one through the fine ones, fitted for every split; the chosen K ends the coarse line of the
  /// best-fitting split.
  /// The range of K is then cut to three times the knee (at least 20 levels) and the search
  /// repeated until the knee stops moving to coarser levels, so that a long flat tail does not
  /// pull it to the right.
  Knee,
  /// One cluster per component (no significant jump, and no knee: fallback off or too few
  /// levels).
  Components,
};

/// A candidate level and how strongly the curve singles it out.
struct LevelCandidate {
  std::uint32_t clusters = 0;  ///< K
  double rms = 0;              ///< rms of the curve at K (input units)
  /// Significance of K, >= 0: the ratio rms(K − 1) / rms(K) of floored RMS values, the jump of
  /// the curve when the next merge is applied (a smooth curve scores about 1). One cluster per
  /// component scores min_score.
  double score = 0;
  /// The jump of the cluster the next merge makes: its RMS over the level's (the larger of rms
  /// and 0.1% of the bounding-box diagonal); 0 for one cluster per component. See
  /// AutoLevelOptions::cluster_jumps.
  double merge_score = 0;
};

/// "jump", "knee" or "components".
std::string_view to_string(AutoLevelRule rule);

/// The chosen level and the candidates.
struct AutoLevel {
  /// The chosen K: the finest level with a significant jump (AutoLevelRule::Jump: of the curve
  /// or of the merged cluster; a coarser jump, however large, only says that the regions of the
  /// finer level are themselves grouped: a small chamfer joining a face is a smaller jump than
  /// two large faces joining, and just as real); when no jump is significant, the knee of the
  /// curve; else one cluster per component (see `rule`).
  std::uint32_t clusters = 0;
  AutoLevelRule rule = AutoLevelRule::Components;  ///< how `clusters` was chosen
  /// Best score first: the best-scored levels, and the chosen one wherever it ranks.
  std::vector<LevelCandidate> candidates;
};

/// Picks the most significant level of the hierarchy from its error curve, among K from the
/// number of components C to max(C, F / 2) (finer levels are left out: there the curve rises
/// from zero, single triangles fitting exactly, and under noise its first ratios are large
/// without meaning anything). One finer level is a candidate too: the coarsest whose every
/// cluster fits exactly (RMS 0), when the next merge raises the RMS to 1% of the bounding-box
/// diagonal or more, as on a polyhedron with few faces each a plane of its own (a tetrahedron
/// gets 4 clusters). Deterministic; O(F log F). Throws InvalidInputError for options
/// out of range (negative or non-finite floor, min_score below 1, no candidate asked for).
AutoLevel choose_level(const Hierarchy& hierarchy, const AutoLevelOptions& options = {});

}  // namespace primseg
