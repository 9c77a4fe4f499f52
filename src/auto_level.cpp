#include "primseg/auto_level.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "primseg/error.hpp"

namespace primseg {

std::vector<ErrorCurvePoint> error_curve(const Hierarchy& hierarchy) {
  const std::uint32_t f = hierarchy.face_count();
  const std::uint32_t real = f - hierarchy.component_count();
  const auto merges = hierarchy.merges();
  // Working-frame sums, as the tree stores them; each merge replaces its children's errors by
  // its own. Weights do not change with K: every level covers every face.
  double error = 0, weight = 0;
  for (std::uint32_t leaf = 0; leaf < f; ++leaf) {
    error += hierarchy.error(leaf);
    weight += hierarchy.weight(leaf);
  }
  const int exponent = hierarchy.graph().frame().exponent;
  auto rms = [&](double e) {
    return weight > 0 ? std::ldexp(std::sqrt(std::max(e, 0.0) / weight), exponent) : 0.0;
  };
  std::vector<ErrorCurvePoint> curve(real + 1);
  curve[real] = {f, rms(error)};
  for (std::uint32_t i = 0; i < real; ++i) {
    const Merge& m = merges[i];
    error += m.error - hierarchy.error(m.first) - hierarchy.error(m.second);
    curve[real - 1 - i] = {f - 1 - i, rms(error)};
  }
  return curve;
}

AutoLevel choose_level(const Hierarchy& hierarchy, const AutoLevelOptions& options) {
  if (!(options.rms_floor >= 0) || !std::isfinite(options.rms_floor))
    throw InvalidInputError("auto level: the RMS floor must be a non-negative number");
  if (!(options.min_score >= 1) || !std::isfinite(options.min_score))
    throw InvalidInputError("auto level: the minimum score must be a number >= 1");
  if (options.max_candidates < 1)
    throw InvalidInputError("auto level: at least one candidate must be asked for");
  const std::vector<ErrorCurvePoint> curve = error_curve(hierarchy);
  const double floor = options.rms_floor * bounding_box_diagonal(hierarchy.mesh());
  // The smallest normal double keeps the ratios finite on a degenerate (zero-size) mesh.
  auto floored = [&](double rms) {
    return std::max({rms, floor, std::numeric_limits<double>::min()});
  };
  const std::uint32_t c = hierarchy.component_count(), f = hierarchy.face_count();
  std::vector<LevelCandidate> candidates{{c, curve[0].rms, options.min_score}};
  // Levels finer than F / 2 are left out: there the curve rises from zero (single triangles fit
  // exactly) and under noise its first ratios are large without meaning anything.
  const std::uint32_t finest = std::max(c, f / 2);
  for (std::uint32_t k = c + 1; k <= finest && k - c < curve.size(); ++k) {
    const double jump = floored(curve[k - 1 - c].rms) / floored(curve[k - c].rms);
    candidates.push_back({k, curve[k - c].rms, jump});
  }
  // The finest significant level: a coarser jump, however large, only says that the regions
  // of the finer level are themselves grouped (a small chamfer merging is a smaller jump than
  // two big faces merging, and is just as real).
  std::uint32_t chosen = c;
  for (const LevelCandidate& candidate : candidates)
    if (candidate.score >= options.min_score) chosen = std::max(chosen, candidate.clusters);
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
  level.candidates = std::move(candidates);
  return level;
}

}  // namespace primseg
