#include "model_selection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "primseg/error.hpp"

namespace primseg {

void validate(const HierarchyOptions& options) {
  if (options.primitives.empty()) throw InvalidInputError("no primitive type enabled");
  for (std::size_t i = 0; i < options.primitives.size(); ++i) {
    const PrimitiveType t = options.primitives[i];
    if (static_cast<int>(t) >= kPrimitiveTypeCount || !has_fitter(t))
      throw InvalidInputError("primitive type '" + std::string(to_string(t)) +
                              "' is not available in this version");
    for (std::size_t j = 0; j < i; ++j)
      if (options.primitives[j] == t)
        throw InvalidInputError("primitive type '" + std::string(to_string(t)) +
                                "' is listed twice");
  }
  for (double p : options.type_penalty)
    if (!(p > 0) || !std::isfinite(p))
      throw InvalidInputError("type penalties must be positive and finite");
  if (!(options.zero_cost_tolerance >= 0) || !std::isfinite(options.zero_cost_tolerance))
    throw InvalidInputError("zero_cost_tolerance must be non-negative and finite");
  if (!(options.merge_batch_tolerance >= 0) || !std::isfinite(options.merge_batch_tolerance))
    throw InvalidInputError("merge_batch_tolerance must be non-negative and finite");
  if (options.regions < 1 || options.regions > 256)
    throw InvalidInputError("regions must be from 1 to 256, not " +
                            std::to_string(options.regions));
  if (options.regions > 1 && options.exact_costs)
    throw InvalidInputError("regions cannot be combined with exact_costs (a reference mode)");
}

namespace detail {
namespace {
// Normal agreements closer than this are equal (round-off of the sums).
constexpr double kAlignmentTieMargin = 1e-6;
}  // namespace

ModelSelector::ModelSelector(const HierarchyOptions& options) : options_(options) {
  validate(options);
  std::vector<PrimitiveType> types = options.primitives;
  std::sort(types.begin(), types.end());
  for (PrimitiveType t : types) {
    fitters_.push_back(&fitter_for(t));
    needs_samples_ = needs_samples_ || fitters_.back()->needs_samples();
    closed_form_ = closed_form_ && fitters_.back()->closed_form();
    if (t != PrimitiveType::Plane)
      min_curved_triangles_ = std::min(min_curved_triangles_, fitters_.back()->min_triangles());
  }
}

double ModelSelector::finish(PrimitiveFit& fit, double zero_level, const ExactError* exact) const {
  if (exact) fit.error = (*exact)(fit.primitive);
  if (fit.error <= zero_level) fit.error = 0;
  return fit.error * options_.type_penalty[static_cast<int>(fit.primitive.type)];
}

SelectedModel ModelSelector::refit(const ClusterView& cluster, PrimitiveType chosen) const {
  // A chosen type's fit was valid, or the type is the plane fallback, which always is.
  SelectedModel model;
  model.fit = fitter_for(chosen).fit(cluster);
  model.cost =
      finish(model.fit, options_.zero_cost_tolerance * cluster.second_moment().trace(), nullptr);
  return model;
}

SelectedModel ModelSelector::select(const ClusterView& cluster, const ExactError* exact) const {
  const double spread = cluster.second_moment().trace();
  const double zero_level = options_.zero_cost_tolerance * spread;
  const bool lazy = options_.evaluation != CandidateEvaluation::Eager && !exact;
  double bound = std::numeric_limits<double>::infinity();  // min over types of penalised bounds
  SelectedModel best;
  bool found = false;
  for (const PrimitiveFitter* fitter : fitters_) {
    if (cluster.triangle_count() < fitter->min_triangles()) {
      bound = 0;  // the type may fit a larger cluster: nothing is known
      continue;
    }
    // A type wins only below the best cost so far: its fit may stop once its error is certainly
    // not below best.cost / penalty. (Not when the error is replaced by the exact one, nor at the
    // zero level, where exact fits tie and normal agreement decides.)
    const double penalty = options_.type_penalty[static_cast<int>(fitter->type())];
    double error_to_beat = std::numeric_limits<double>::infinity();
    if (found && !exact && best.cost / penalty > zero_level) error_to_beat = best.cost / penalty;
    PrimitiveFit fit = fitter->fit(cluster, error_to_beat);
    if (lazy) bound = std::min(bound, fit.superset_error_bound * penalty);
    if (!fit.valid || !std::isfinite(fit.error)) continue;
    const double cost = finish(fit, zero_level, exact);
    // Exact fits tie at cost 0: the vertices of a coarse tessellation lie exactly on several
    // surfaces (a band between two circles lies on a cone, a sphere and tori), but the face
    // normals follow only the true one. Among exact fits the better normal agreement wins;
    // other ties keep the earlier (simpler) type.
    const bool better_exact =
        found && cost == 0 && best.cost == 0 &&
        fit.normal_alignment > best.fit.normal_alignment + kAlignmentTieMargin;
    if (!found || cost < best.cost || better_exact) {
      best.fit = fit;
      best.cost = cost;
      found = true;
    }
    // Costs are never negative: nothing after an exact fit whose normals agree everywhere (a
    // flat plane) can win, so the richer fits need not run (most candidates in flat regions).
    if (found && best.cost == 0 && best.fit.normal_alignment >= 1 - kAlignmentTieMargin) break;
  }
  if (!found) {
    best.fit = fitter_for(PrimitiveType::Plane).fit(cluster);
    best.cost = finish(best.fit, zero_level, exact);
  }
  if (lazy && best.cost > 0 && bound > 0) {
    // Round-off in the fits is of order 1e-16 of the spread; the margin keeps the bound below
    // every computed cost of a superset.
    const double max_penalty =
        *std::max_element(options_.type_penalty.begin(), options_.type_penalty.end());
    best.superset_cost_bound = std::max(0.0, bound - 1e-10 * max_penalty * spread);
  }
  return best;
}

}  // namespace detail
}  // namespace primseg
