#pragma once
/// @file primitive_fitter.hpp
/// The plug-in interface every primitive type implements. The engine knows primitives only
/// through it: adding a type means adding one fitter and registering it in fitter_for().

#include <cstdint>
#include <limits>
#include <string_view>
#include <vector>

#include "primseg/cluster_stats.hpp"
#include "primseg/cluster_view.hpp"
#include "primseg/primitive.hpp"

namespace primseg {

/// One primitive type fitted to a cluster's statistics, in the working frame.
struct PrimitiveFit {
  /// False when this type cannot honestly represent the cluster: too little support, a
  /// degenerate configuration (no axis, flat data for a curved type, a radius beyond the
  /// plausible range). An invalid fit never wins a merge.
  bool valid = false;
  /// L2 error Σ w d², exact for planes and a first-order equivalent for curved types (see each
  /// fitter), in working-frame units (weight × length²).
  double error = std::numeric_limits<double>::infinity();
  /// Fitted parameters in the working frame.
  Primitive primitive;
  /// A lower bound of this type's error for every cluster that contains this one, whatever the
  /// validity rules decide (working-frame units). It holds where the error is an exact minimum
  /// over the type's parameters of a sum of non-negative per-point terms (plane, Pratt sphere);
  /// 0 where no bound is known. Lets the hierarchy leave candidates unevaluated (lazy mode).
  double superset_error_bound = 0;
  /// True when the fit stopped early because its error is at least the error to beat (see
  /// PrimitiveFitter::fit); then valid is false and the error is not known.
  bool beaten = false;
  /// How well the face normals follow the primitive's (ClusterStats::normal_alignment for the
  /// curved types, |Σ A n| / Σ A for a plane): 1 when they agree everywhere. Breaks ties between
  /// exact fits (see ModelSelector).
  double normal_alignment = 1;
};

/// A primitive type's fitter.
class PrimitiveFitter {
 public:
  virtual ~PrimitiveFitter() = default;
  virtual PrimitiveType type() const = 0;
  /// Fewest triangles a cluster needs before this type is fitted at all: below it every cluster
  /// fits exactly (two triangles always lie on a sphere), which says nothing about the shape.
  virtual std::uint32_t min_triangles() const = 0;
  /// Fits the type to a cluster, or to the union of two (a merge candidate). `error_to_beat`:
  /// the type cannot win the cluster unless its error is below this (another type has that
  /// cost), so a fitter may stop as soon as its error is certainly at least this and return an
  /// invalid fit with `beaten` set and superset_error_bound at most its error. Infinity: fit
  /// fully. A fit that is not beaten must be the same, bit for bit, as with an infinite
  /// error_to_beat (the hierarchy refits the winning type alone when it applies a merge).
  virtual PrimitiveFit fit(const ClusterView& cluster, double error_to_beat) const = 0;
  PrimitiveFit fit(const ClusterView& cluster) const {
    return fit(cluster, std::numeric_limits<double>::infinity());
  }
  /// Fits the type to statistics whose moments are centred at the cluster's centroid.
  PrimitiveFit fit(const ClusterStats& centred) const { return fit(ClusterView(centred)); }
  /// Whether the fit reads ClusterStats::samples (then the engine keeps them, at a memory cost).
  virtual bool needs_samples() const { return false; }
  /// Whether a fit is (nearly) a closed form of the statistics: a few small eigen-problems and
  /// solves, about a microsecond (plane, sphere, cylinder), rather than an iterative solve of
  /// tens of microseconds (cone, torus: Levenberg–Marquardt). Only where some enabled type is
  /// iterative does the hierarchy share a merge's few candidates among threads: cheap ones cost
  /// less on the calling thread than handed to another core.
  virtual bool closed_form() const { return true; }
};

/// Curved fits must agree with the face normals (ClusterStats::normal_alignment at least this):
/// the vertices of a coarse CAD triangulation lie exactly on many wrong surfaces (the rim of a
/// flat cap lies on the cylinder it closes; two faces of a box corner on a circle through three
/// points), but their faces' normals do not follow those surfaces. 0.9 admits facets spanning up
/// to about 50 degrees of arc.
inline constexpr double kMinNormalAlignment = 0.9;

/// The fitter of a type. Throws InvalidInputError for a type without one.
const PrimitiveFitter& fitter_for(PrimitiveType type);

/// Whether a type has a fitter in this build.
bool has_fitter(PrimitiveType type);

/// The type named `name` (to_string()'s spelling, lower case), for a type with a fitter. The one
/// parser of type names for the CLI, the Python module and the benchmarks.
/// Throws InvalidInputError "unknown primitive 'NAME' (available: 'plane', 'cylinder', ...)",
/// listing the types with a fitter in enum order, for any other name (an empty one included).
PrimitiveType fittable_type_from_string(std::string_view name);

/// The types named in a comma-separated list ("plane,sphere"), in its order, each as
/// fittable_type_from_string() reads it: an empty list or an empty item is an unknown name ''.
/// Repeated types are kept (HierarchyOptions' validation refuses them).
std::vector<PrimitiveType> fittable_types_from_list(std::string_view list);

/// Flips a unit direction so that its largest-magnitude component is positive (first such
/// component on ties): the canonical sign of cylinder, cone and torus axes.
Eigen::Vector3d canonical_axis(const Eigen::Vector3d& axis);

}  // namespace primseg
