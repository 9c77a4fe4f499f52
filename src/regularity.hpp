#pragma once
// Relations between the primitives of a segmentation, and the refit that makes them exact (after
// GlobFit, Li et al. 2011): planes' normals and cylinders' axes that agree within their fits'
// uncertainty share one direction, estimated from all of them, directions at right angles within
// it are made orthogonal, planes of one direction whose offsets agree are made one plane, cylinders
// of one direction whose axes agree share one axis line, spheres centred on such a line within it
// are centred on it, and cylinders and spheres whose radii agree share one radius. The stages are
// in src/regularity/, one source each (src/regularity/stages.hpp).

#include <cstddef>
#include <span>
#include <vector>

#include "primseg/primitive.hpp"
#include "primseg/relations.hpp"

namespace primseg::detail {

struct RegularityOptions {
  /// A direction joins a group when its tilt from the group's direction is within this many
  /// standard deviations: its squared Mahalanobis distance (both estimates' covariances) within
  /// chi_square_bound() of 2 degrees of freedom. Every test takes the bound of its degrees of
  /// freedom, a true relation failing each as rarely as a normal deviate beyond this. > 0.
  double significance = 3;
  /// ... and never farther than this, whatever the uncertainty (degrees); the same bounds make
  /// two directions orthogonal.
  double max_angle_degrees = 20;
  /// Directions within this angle of one another are parallel, and within it of a right angle
  /// orthogonal, whatever their uncertainty (radians, >= 0): a CAD tessellation's directions err
  /// systematically, by more than their fits' statistics allow. 0: the statistics alone.
  double angle_tolerance = 0;
  /// Likewise for lengths (the points' units, >= 0): axis lines, sphere centres on lines, plane
  /// offsets, radii and tangency gaps this close agree, and a joint fit that raises a member's mean
  /// square residual by at most its square keeps the member. 0: the statistics alone.
  double length_tolerance = 0;
  /// Make directions at right angles within the significance exactly orthogonal.
  bool orthogonal = true;
  /// Make planes of one direction whose offsets along it agree within the significance one
  /// plane (the fragments of one face): one offset instead of one each.
  bool coplanar = true;
  /// Centre a sphere whose centre is on a cylinder's axis line within the significance on it (a
  /// ball end, a hemispherical cap): one parameter along the line instead of three; and three
  /// spheres or more on one line of a direction made exact (a revolved profile's arcs).
  bool spheres_on_axes = true;
  /// Give spheres on no line whose centres agree within the significance one centre, each
  /// keeping its radius (a ball and its socket): 3 parameters for the set instead of 3 each; and
  /// spheres on one line whose places along it agree one place (a ball and its socket on a
  /// shaft's axis). With equal_radii, those whose radii agree too take one radius (fragments of
  /// one sphere).
  bool concentric = true;
  /// Give cylinders and spheres whose radii agree within the significance one radius, concentric
  /// spheres included.
  bool equal_radii = true;
  /// ... never when the radii differ by more than this fraction of the larger, nor a radius
  /// whose significance interval is wider than this fraction of it; likewise a sphere's centre's
  /// distance from an axis line, as a fraction of the sphere's radius, and the gap between a
  /// cylinder's radius and its axis's distance from a plane it is to be tangent to.
  double max_radius_difference = 0.05;
  /// Hold a cylinder tangent to the planes it borders whose distance from its axis is its radius
  /// within the significance, its direction made exactly orthogonal to theirs (a fillet, a slot's
  /// round end): 2 parameters for one plane, 1 for two; and tangent to a cylinder of its
  /// direction group with more points that it borders (a fillet around a boss or in a bore).
  bool tangency = true;
};

/// Primitives that regularize() made share a direction, an axis line or a radius, or made
/// orthogonal. The kinds are the public ones (ClusterRelation::Kind).
struct Relation {
  using Kind = ClusterRelation::Kind;
  Kind kind = Kind::Parallel;
  std::vector<std::size_t> members;  ///< indices into the primitives, increasing; two or more
                                     ///< (Orthogonal: one or more)
  std::vector<std::size_t> others;   ///< Orthogonal: the other direction's, increasing
};

/// Groups the directions of `primitives` (plane normals, cylinder axes; other types are left as
/// they are), makes the groups' directions that are at right angles within the significance
/// exactly orthogonal (RegularityOptions::orthogonal), and refits every member of a group of two
/// or more, or of a group in a right angle, with the group's direction: a plane through its
/// inliers' weighted centroid, or with the planes coplanar with it through all their inliers
/// (RegularityOptions::coplanar: one offset; the set counts as one plane in the group's direction,
/// before the right angles), a cylinder by geometric least squares of its inliers' circle,
/// jointly with the cylinders coaxial with it (one axis line, one radius each). points[c] and
/// weights[c] are cluster c's inlier vertices (input units) and their weights; a cluster with too
/// few to estimate its direction's uncertainty is left alone. Deterministic: clusters are visited
/// by increasing uncertainty, ties by index. Then spheres centred on an axis line within the
/// significance (RegularityOptions::spheres_on_axes) are refitted with their line's cylinders,
/// one parameter along it each, as are three spheres or more centred on one line of a direction
/// made exact with no cylinder on it, and cylinders and spheres whose radii agree within the
/// significance (RegularityOptions::equal_radii) are refitted with one radius, jointly with the
/// surfaces on their lines and centres; before that, spheres on no line whose centres agree within
/// the significance share one, and spheres on one line whose places along it agree share one
/// (RegularityOptions::concentric), which they keep when their radii join classes (a sphere cut
/// apart: its fragments then share both). Returns the relations made exact: each direction group's
/// members that were refitted with its direction, then its coplanar sets, then each coaxial set of
/// its cylinders (spheres added when they join it), in that order, then the coaxial sets a sphere
/// started with one cylinder, then the lines of spheres alone, then the concentric sets (off
/// lines, then on them), then the classes of equal radii, then the right angles by their members.
/// Last, cylinders whose direction a right angle made exactly orthogonal to a plane's, that border
/// the plane and whose axis is at their radius from it within the significance are refitted tangent
/// to it (RegularityOptions::tangency; the cylinders of a coaxial set together, on their one line,
/// not a line with spheres on it; one of a class of equal radii with members off its line keeps
/// that radius), each on its points away from the band about the contact line where the two
/// surfaces are within the noise (the plane's offset refitted so, unless it is a coplanar set's):
/// each pair is a Tangent relation, by line. Direction groups the right angles made one direction
/// are merged first. Every test "within the significance" also passes a difference within the angle
/// or length tolerance (RegularityOptions::angle_tolerance, length_tolerance), and every check that
/// a joint fit explains a member as its own did also passes a rise of its mean square residual
/// within the length tolerance's square.
std::vector<Relation> regularize(std::vector<Primitive>& primitives,
                                 const std::vector<std::vector<Vec3>>& points,
                                 const std::vector<std::vector<double>>& weights,
                                 const RegularityOptions& options);

/// Orders relations by kind (ClusterRelation::Kind's order), then by their clusters.
void sort_relations(std::vector<ClusterRelation>& relations);

/// A cluster's inliers: its points within `threshold` robust deviations (1.4826 × the median
/// distance, at least `floor`) of `primitive`, with their weights. `points` is not empty.
void keep_inliers(const Primitive& primitive, std::span<const Vec3> points,
                  std::span<const double> weights, double threshold, double floor,
                  std::vector<Vec3>& kept_points, std::vector<double>& kept_weights);

/// regularize() on clusters' inliers (keep_inliers()), as relations between the indices of
/// `primitives` in sort_relations() order, each with its deviation (ClusterRelation::deviation;
/// lengths in the points' units).
std::vector<ClusterRelation> regularize_kept(std::vector<Primitive>& primitives,
                                             const std::vector<std::vector<Vec3>>& inlier_points,
                                             const std::vector<std::vector<double>>& inlier_weights,
                                             const RegularityOptions& options);

/// regularize() on each cluster's inliers (keep_inliers() of points[c], weights[c] about
/// primitives[c]; an empty cluster stays out), as relations between the indices of `primitives`
/// in sort_relations() order.
std::vector<ClusterRelation> regularize_inliers(std::vector<Primitive>& primitives,
                                                const std::vector<std::vector<Vec3>>& points,
                                                const std::vector<std::vector<double>>& weights,
                                                double outlier_threshold, double floor,
                                                const RegularityOptions& options);

}  // namespace primseg::detail
