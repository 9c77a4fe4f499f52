#include "primseg/auto_level.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "primseg/error.hpp"

namespace primseg {
namespace {

// The knee search never narrows the curve below this many levels: a few points past a knee
// are not enough for the right-hand line.
constexpr std::size_t kMinKneeRange = 20;

// An exact level finer than F / 2 counts only if joining two of its clusters raises the RMS of
// the whole level to at least this fraction of the bounding-box diagonal: a polyhedron with few
// faces, each its own plane. Noise leaves nothing exact above single triangles, and two noisy
// triangles joined raise the RMS of a mesh of any size far less.
constexpr double kExactLevelMinJumpRms = 1e-2;

// A cluster jump (AutoLevelOptions::cluster_jumps) needs the level's RMS to rise by this factor
// at least, the level to lie on the noise plateau (rms(K) / rms(min(2K, F)) at most
// kPlateauMaxDrop), and is measured against at least this fraction of the diagonal. Chosen on the
// generated shapes (seeds 1 to 3; seeds 4 to 9 held out gave the same gains) and checked on 126
// meshes of libcgal-demo, of which only oblong.off moved (30 -> 40 clusters, a level that fits).
// A noisy fillet's or chamfer's merge raises its level's RMS by 1.3 to 1.9 and makes a cluster 2
// to 4 times the level's, on a plateau of 1.00 to 1.11; fandisk's curve keeps falling (rms(24) /
// rms(48) is 6), and the exact levels of the uniform chamfered cylinder, whose cone the default
// types cannot fit, misfit by less than 0.1% of the diagonal (docs/method.md, "Jumps of the
// merged cluster").
constexpr double kClusterJumpMinScore = 1.25;
constexpr double kPlateauMaxDrop = 1.15;
constexpr double kClusterJumpRmsFloor = 1e-3;

// Sums of a run of points (x, y), for the least-squares line through them in O(1).
struct LineSums {
  double n = 0, x = 0, y = 0, xx = 0, xy = 0, yy = 0;
  void add(double px, double py) {
    n += 1;
    x += px;
    y += py;
    xx += px * px;
    xy += px * py;
    yy += py * py;
  }
  LineSums minus(const LineSums& o) const {
    return {n - o.n, x - o.x, y - o.y, xx - o.xx, xy - o.xy, yy - o.yy};
  }
  // Slope of the least-squares line (0 without spread in x).
  double slope() const {
    const double sxx = n > 0 ? xx - x * x / n : 0;
    return sxx > 0 ? (xy - x * y / n) / sxx : 0;
  }
  // Root-mean-square residual of the least-squares line (0 for two points or fewer).
  double line_rms() const {
    if (n < 3) return 0;
    const double sxx = xx - x * x / n, sxy = xy - x * y / n, syy = yy - y * y / n;
    const double residual = sxx > 0 ? syy - sxy * sxy / sxx : syy;
    return std::sqrt(std::max(residual, 0.0) / n);
  }
};

// The L-method (Salvador and Chan 2004) on points (x_i, y_i), i in [0, count): the split after
// which two least-squares lines, one through the points up to it and one through the rest, fit
// best (each line's RMS residual weighted by its share of the points). Returns the index of the
// last point of the left line; both lines get at least two points.
std::size_t l_method_knee(const std::vector<double>& x, const std::vector<double>& y,
                          std::size_t count) {
  std::vector<LineSums> prefix(count + 1);
  for (std::size_t i = 0; i < count; ++i) {
    prefix[i + 1] = prefix[i];
    prefix[i + 1].add(x[i], y[i]);
  }
  std::size_t best = 1;
  double best_fit = std::numeric_limits<double>::infinity();
  for (std::size_t last = 1; last + 2 < count; ++last) {
    const LineSums left = prefix[last + 1], right = prefix[count].minus(prefix[last + 1]);
    const double fit =
        (left.n * left.line_rms() + right.n * right.line_rms()) / static_cast<double>(count);
    if (fit < best_fit) {
      best_fit = fit;
      best = last;
    }
  }
  return best;
}

// The knee of log(floored rms) against K over K in [c, finest] (see AutoLevelRule::Knee), or
// nullopt when the curve has no significant bend.
template <typename Floored>
std::optional<std::uint32_t> curve_knee(const std::vector<ErrorCurvePoint>& curve, std::uint32_t c,
                                        std::uint32_t finest, const Floored& floored,
                                        const AutoLevelOptions& options) {
  std::vector<double> x, y;
  for (std::uint32_t k = c; k <= finest && k - c < curve.size(); ++k) {
    x.push_back(static_cast<double>(k));
    y.push_back(std::log(floored(curve[k - c].rms)));
  }
  if (x.size() < 4) return std::nullopt;
  // The search starts at levels of ten faces per cluster on average: finer, the curve falls
  // towards zero as clusters shrink to a few triangles that fit exactly, a second knee that says
  // nothing about the surfaces. Then, as the L-method prescribes, the range is cut to three
  // times the knee, until the knee stops moving to coarser levels: a long tail pulls it right.
  const std::size_t faces = curve.back().clusters;
  std::size_t count =
      std::clamp<std::size_t>(faces / 10, std::min(kMinKneeRange, x.size()), x.size());
  std::size_t knee = count;
  for (int round = 0; round < 32 && count >= 4; ++round) {
    const std::size_t found = l_method_knee(x, y, count);
    if (found >= knee) break;
    knee = found;
    count = std::min(x.size(), std::max<std::size_t>(3 * knee + 1, kMinKneeRange));
  }
  // A knee needs finer levels after it (knee == count: no split was tried at all).
  if (knee + 2 >= count) return std::nullopt;
  // Significant only if the curve falls by at least min_score down to the knee, and the coarse
  // line is at least min_score times steeper than the fine one: a curve that only wavers (one
  // noisy sphere) or falls evenly has a best split too, but no bend.
  LineSums left, right;
  for (std::size_t i = 0; i < count; ++i) (i <= knee ? left : right).add(x[i], y[i]);
  const double fall = y[0] - y[knee];
  if (!(fall >= std::log(options.min_score))) return std::nullopt;
  if (!(-left.slope() >= options.min_score * std::max(-right.slope(), 0.0))) return std::nullopt;
  return c + static_cast<std::uint32_t>(knee);
}

}  // namespace

std::string_view to_string(AutoLevelRule rule) {
  switch (rule) {
    case AutoLevelRule::Jump:
      return "jump";
    case AutoLevelRule::Knee:
      return "knee";
    case AutoLevelRule::Components:
      break;
  }
  return "components";
}

std::vector<ErrorCurvePoint> error_curve(const Hierarchy& hierarchy) {
  const std::uint32_t f = hierarchy.face_count();
  const std::uint32_t real = f - hierarchy.component_count();
  const auto merges = hierarchy.merges();
  // Working-frame sums, as the tree stores them; each merge replaces its children's errors by
  // its own. Weights do not change with K: every level covers every face.
  // A leaf's error is a fit (leaves are not stored): each is computed once.
  std::vector<double> leaf_error(f);
  double error = 0, weight = 0;
  for (std::uint32_t leaf = 0; leaf < f; ++leaf) {
    error += leaf_error[leaf] = hierarchy.error(leaf);
    weight += hierarchy.weight(leaf);
  }
  auto error_of = [&](std::uint32_t node) {
    return node < f ? leaf_error[node] : hierarchy.error(node);
  };
  const int exponent = hierarchy.graph().frame().exponent;
  auto rms = [&](double e) {
    return weight > 0 ? std::ldexp(std::sqrt(std::max(e, 0.0) / weight), exponent) : 0.0;
  };
  std::vector<ErrorCurvePoint> curve(real + 1);
  curve[real] = {f, rms(error)};
  for (std::uint32_t i = 0; i < real; ++i) {
    const Merge& m = merges[i];
    error += m.error - error_of(m.first) - error_of(m.second);
    curve[real - 1 - i] = {f - 1 - i, rms(error)};
  }
  return curve;
}

AutoLevel choose_level(const Hierarchy& hierarchy, const AutoLevelOptions& options) {
  if (!(options.rms_floor >= 0) || !std::isfinite(options.rms_floor))
    throw InvalidInputError("auto level: the RMS floor must be a non-negative number");
  if (!(options.knee_rms_floor >= 0) || !std::isfinite(options.knee_rms_floor))
    throw InvalidInputError("auto level: the knee's RMS floor must be a non-negative number");
  if (!(options.min_score >= 1) || !std::isfinite(options.min_score))
    throw InvalidInputError("auto level: the minimum score must be a number >= 1");
  if (options.max_candidates < 1)
    throw InvalidInputError("auto level: at least one candidate must be asked for");
  const std::vector<ErrorCurvePoint> curve = error_curve(hierarchy);
  const double diagonal = bounding_box_diagonal(hierarchy.mesh());
  // RMS values raised to a fraction of the diagonal; the smallest normal double keeps the ratios
  // finite on a degenerate (zero-size) mesh.
  auto floor_at = [diagonal](double fraction) {
    return [floor = fraction * diagonal](double rms) {
      return std::max({rms, floor, std::numeric_limits<double>::min()});
    };
  };
  const auto floored = floor_at(options.rms_floor);
  const std::uint32_t c = hierarchy.component_count(), f = hierarchy.face_count();
  // Level k (c < k <= f) and the jump of the cluster its next merge makes (merges[f - k]: the
  // first f - k merges give level k, all of them real).
  const double merge_floor = kClusterJumpRmsFloor * diagonal;
  auto level_at = [&](std::uint32_t k, double score) {
    const double rms = curve[k - c].rms;
    const double merged = hierarchy.rms_estimate(f + (f - k));
    return LevelCandidate{k, rms, score, merged / std::max(merge_floor, floored(rms))};
  };
  std::vector<LevelCandidate> candidates{{c, curve[0].rms, options.min_score}};
  // Levels finer than F / 2 are left out: there the curve rises from zero (single triangles fit
  // exactly) and under noise its first ratios are large without meaning anything.
  const std::uint32_t finest = std::max(c, f / 2);
  for (std::uint32_t k = c + 1; k <= finest && k - c < curve.size(); ++k)
    candidates.push_back(level_at(k, floored(curve[k - 1 - c].rms) / floored(curve[k - c].rms)));
  auto significant = [&](const LevelCandidate& level) {
    if (level.score >= options.min_score) return true;  // one cluster per component, too
    if (!options.cluster_jumps) return false;
    const auto twice =
        static_cast<std::uint32_t>(std::min<std::uint64_t>(2ull * level.clusters, f));
    return level.score >= kClusterJumpMinScore && level.merge_score >= options.min_score &&
           floored(level.rms) <= kPlateauMaxDrop * floored(curve[twice - c].rms);
  };
  // Except the coarsest exact level, when it is finer than that and far from noise (a
  // tetrahedron: four triangles, four planes).
  if (f > finest) {
    std::uint32_t exact = f;
    while (exact > finest + 1 && curve[exact - 1 - c].rms == 0) --exact;
    const double joined_rms = curve[exact - 1 - c].rms;
    if (curve[exact - c].rms == 0 && joined_rms > 0 &&
        joined_rms >= kExactLevelMinJumpRms * diagonal)
      candidates.push_back(level_at(exact, floored(joined_rms) / floored(0.0)));
  }
  // The finest significant level: a coarser jump, however large, only says that the regions
  // of the finer level are themselves grouped (a small chamfer merging is a smaller jump than
  // two big faces merging, and is just as real).
  std::uint32_t chosen = c;
  for (const LevelCandidate& level : candidates)
    if (significant(level)) chosen = std::max(chosen, level.clusters);
  AutoLevelRule rule = chosen > c ? AutoLevelRule::Jump : AutoLevelRule::Components;
  // No jump: the knee of log rms against K. Real parts with blends descend steadily while
  // merges join different surfaces, and flatten once they only join pieces of one surface.
  if (rule == AutoLevelRule::Components && options.knee_fallback) {
    const std::optional<std::uint32_t> knee =
        curve_knee(curve, c, finest, floor_at(options.knee_rms_floor), options);
    if (knee) {
      chosen = *knee;
      rule = AutoLevelRule::Knee;
    }
  }
  std::stable_sort(
      candidates.begin(), candidates.end(),
      [](const LevelCandidate& a, const LevelCandidate& b) { return a.score > b.score; });
  // The best-scored ones, and the chosen one wherever it ranks.
  std::vector<LevelCandidate> kept;
  for (const LevelCandidate& candidate : candidates)
    if (kept.size() < options.max_candidates || candidate.clusters == chosen)
      kept.push_back(candidate);
  candidates = std::move(kept);
  AutoLevel level;
  level.clusters = chosen;
  level.rule = rule;
  level.candidates = std::move(candidates);
  return level;
}

}  // namespace primseg
