#pragma once
/// @file relations.hpp
/// Design intent between the fitted primitives of a segmentation: plane normals and cylinder axes
/// that agree within their fits' uncertainty (opposite faces of a box, a shaft and its end faces),
/// directions at right angles, planes in one plane (the fragments of one face cut apart by holes),
/// cylinders that share an axis line and spheres centred on it (a stepped shaft, the fragments of
/// one bore, a ball end, a hole's spherical seat) and cylinders and spheres of one radius (a bolt
/// circle's holes), and cylinders tangent to the planes they border (a fillet, a slot's round end)
/// or to the parallel cylinders they border (a fillet around a boss or in a bore), and spheres
/// of one centre (a ball and its socket, a spherical shell's two sides).
/// Making these relations exact is what reverse engineering wants of a scanned part's fits: a box
/// with parallel faces, a flange face in one plane, a shaft with one axis, a fillet tangent to its
/// faces (after GlobFit, Li et al. 2011).

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/hierarchy.hpp"

namespace primseg {

/// A relation between clusters' primitives, made exact.
struct ClusterRelation {
  enum class Kind {
    /// Plane normals and cylinder axes made one direction (each keeps its side): opposite faces
    /// of a box, a cylinder and its caps.
    Parallel,
    /// Cylinders of one direction made one axis line, each keeping its radius, and spheres
    /// centred on that line, each keeping its radius and its place along it (spheres of one place,
    /// a ball and its socket on a shaft's axis, are also a Concentric relation): a stepped shaft,
    /// the
    /// fragments of one cylinder, a shaft's ball end, the hemisphere closing a cylinder, a hole's
    /// spherical seat. Two or more cylinders are also part of a Parallel relation. A set without
    /// a cylinder has three spheres or more, centred on a line of a direction of the part (one a
    /// Parallel or Orthogonal relation made exact): the arcs of a revolved profile.
    Coaxial,
    /// Two directions made exactly orthogonal: `clusters` have one (a plane's normal or a
    /// cylinder's axis), `orthogonal_to` the other. A box's three directions give three of
    /// these; a shaft's axis and the faces along it, one.
    Orthogonal,
    /// Cylinders and spheres made one radius, each keeping its own axis line or centre: the holes
    /// of a bolt circle, fillets of one radius, the spherical seats of a pattern, a cylinder and
    /// the hemisphere that closes it, the fragments of one cylinder (which are coaxial too).
    EqualRadius,
    /// Planes of one direction made one plane, each keeping its side: the fragments of one face
    /// cut apart by a hole, a boss, a slot or the hierarchy. They are also part of a Parallel
    /// relation.
    Coplanar,
    /// A cylinder held tangent to a plane it borders, its axis orthogonal to the plane's normal
    /// and at its radius from the plane: a fillet and each face it rounds, a slot's round end and
    /// its sides. `clusters` are the two (one cylinder, one plane); a cylinder tangent to two
    /// planes has two such relations. Its direction is also in an Orthogonal relation with the
    /// plane's. The cylinders of a Coaxial set (fragments of one fillet, a lug's round end and
    /// the hole through it) stay on their one line; one whose radius an EqualRadius set shares
    /// with clusters off that line keeps that radius. Not for a line with spheres centred on it.
    /// Also two cylinders of one direction (a Parallel relation) that border each other, their
    /// axes the sum of their radii apart (a fillet around a boss, an arc of a profile blending
    /// into another) or the difference (a fillet inside a bore): the one with fewer vertices is
    /// refitted tangent to the other, which is held as the other relations left it.
    Tangent,
    /// Spheres made one centre, each keeping its radius: a ball and its socket, the two sides of a
    /// spherical shell, a sphere cut apart by the hierarchy. Spheres centred on a line (Coaxial)
    /// are concentric when they share their place along it. Its spheres whose radii agree
    /// (fragments of one sphere) are in an EqualRadius relation too, with any other cylinders and
    /// spheres of that radius.
    Concentric,
  };
  Kind kind = Kind::Parallel;
  /// Cluster labels, increasing; two or more (Orthogonal: one or more, its lowest below the
  /// lowest of `orthogonal_to`).
  std::vector<std::uint32_t> clusters;
  /// Orthogonal: the clusters of the other direction, increasing; empty otherwise.
  std::vector<std::uint32_t> orthogonal_to;
  /// How far the clusters' own fits were from the relation before it was made exact: about what
  /// a tolerance (RelationOptions::angle_tolerance_degrees, length_tolerance) must reach for the
  /// relation to hold whatever the statistics (the tests judge refits on the clusters' inliers,
  /// so the two differ a little). Degrees for Parallel (the largest angle of a member's own
  /// direction from the shared one) and Orthogonal (the largest departure from a right angle
  /// between a member of each side); input units for Coaxial (the largest distance of a member's
  /// own axis, at its point, or centre from the shared line), EqualRadius (the largest difference
  /// of two members' radii), Coplanar (the largest distance of a member's own centroid from the
  /// shared plane), Tangent (the cylinder's own gap: its axis's distance from the plane, at
  /// its point, minus its radius, in absolute value; for two cylinders, the distance of the
  /// smaller one's axis, at its point, from the larger's, minus the sum or the difference of
  /// their radii, whichever is nearer); Concentric (the largest distance of a member's own centre
  /// from the shared one).
  double deviation = 0;
};

/// "parallel", "coaxial", "orthogonal", "equal_radius", "coplanar", "tangent" or "concentric".
std::string_view to_string(ClusterRelation::Kind kind);

/// Options of regularize_clusters().
struct RelationOptions {
  /// A direction joins a group when its tilt from the group's direction is within this many
  /// standard deviations of the two estimates: its squared Mahalanobis distance (both estimates'
  /// covariances) at most the χ² bound that a tilt's two degrees of freedom exceed as rarely as
  /// one normal deviate exceeds this (11.8 at 3). Every test of a relation is calibrated so, by
  /// its degrees of freedom: a true relation is refused with the two-sided normal tail of this
  /// (0.27% at 3), for clusters of a hundred points or more; smaller ones more often, as their
  /// noise is estimated from their own points (a plane of 16 points: 1.35%). Larger joins more.
  /// > 0.
  double significance = 3.0;
  /// ... and never when the tilt is larger than this, whatever the uncertainty (degrees, in
  /// (0, 90)).
  double max_angle_degrees = 20.0;
  /// Directions within this angle of one another join one group, and two within it of a right
  /// angle are made orthogonal, whatever the significance says (degrees, in [0,
  /// max_angle_degrees)). A CAD tessellation's directions are known so precisely that its
  /// systematic error, which more points do not average out, is many deviations: set this to the
  /// part's angular tolerance to make such directions exact. 0: the significance alone.
  double angle_tolerance_degrees = 0.0;
  /// Likewise for lengths (input units, finite, >= 0): axis lines whose positions, planes whose
  /// offsets, spheres whose centres (from a line) and radii that agree within this much, and a
  /// cylinder whose gap to a plane it borders is within it, are related whatever the significance
  /// says, and a member whose mean square residual a joint fit raises by at most its square stays
  /// in its set. The other bounds (max_angle_degrees, max_radius_difference) still apply. 0: the
  /// significance alone.
  double length_tolerance = 0.0;
  /// Cylinders' and spheres' radii are made equal when they agree within the significance, and
  /// never when they differ by more than this fraction of the larger (in (0, 1)). A radius known
  /// less well than that (significance × its standard deviation above this fraction of it: a
  /// cylinder patch of a freeform surface) takes part in none. The same fraction of a sphere's
  /// radius bounds its centre's distance from a cylinder's axis, and how well that distance must
  /// be known, for the sphere to be centred on the axis; and of a cylinder's radius, the gap
  /// between it and its axis's distance from a plane (or from a parallel cylinder's axis, against
  /// the sum or the difference of their radii), for the cylinder to be made tangent to it, and
  /// how far the tangent refit may move each radius on the cylinder's line.
  double max_radius_difference = 0.05;
  /// The directions and the refits use each cluster's inlier vertices: those within this many
  /// robust deviations (1.4826 × the median distance) of its primitive. > 0.
  double outlier_threshold = 2.5;
};

/// Throws InvalidInputError when an option is out of its range.
void validate(const RelationOptions& options);

/// Finds the parallel, orthogonal, coplanar, coaxial, equal-radius and tangent relations among the
/// primitives of a level's clusters and makes them exact, in place.
///
/// `reports` are the level's clusters as describe_clusters() or refine_boundaries() report them
/// (reports[c] is label c of `segmentation`; shape (K)). Planes and cylinders take part, and
/// spheres in the coaxial sets and the equal radii. Each cluster's direction and its uncertainty
/// come from its inlier vertices (each mesh vertex once, weighted by its corners' weights in the
/// hierarchy); clusters with too few vertices to estimate it (6 for a plane, 12 for a cylinder)
/// stay out. Every member of a relation is refitted: a plane through its inliers' weighted centroid
/// with the group's normal, or with its coplanar fragments through all their inliers (one offset;
/// a coplanar set counts as one plane in the group's normal), a cylinder by geometric least squares
/// with the group's axis direction, jointly with the cylinders and spheres coaxial with it (one
/// axis line; one radius each, and each sphere one position along the line; the cylinders of a
/// coaxial set, fitted on one line, count as one in the group's direction) and the cylinders and
/// spheres of equal radius (one radius, each on its own line or centre); last, a cylinder whose
/// direction a right angle made orthogonal to a plane's normal, that shares a vertex with the
/// plane and whose axis is at its radius from it within the significance (and within
/// `max_radius_difference` of the radius, known to better than that) is refitted tangent to it,
/// with the cylinders coaxial with it on their one line (a likelihood-ratio test of the refit
/// decides; a line with spheres on it stays as it is), each fitted on its points away from the band
/// about their contact line where the two surfaces are within the noise of each other (the plane
/// keeps its normal, and its offset unless a coplanar set shares it); likewise tangent to a
/// cylinder of its direction group that it borders and that has more vertices, held as it is (the
/// larger lines first, so that a held cylinder is where it ends). Its report's
/// `primitive`, `rms` and `max` are replaced (`rms` and `max` measured as describe_clusters() does,
/// on all the cluster's vertices); every other report is left bit for bit. Deterministic, O(F log
/// F). Every test "within the significance" also passes a difference within
/// `angle_tolerance_degrees` or `length_tolerance` (RelationOptions), and the refit's test too
/// when it raises a member's RMS by at most `length_tolerance` in quadrature.
///
/// Returns the relations made exact, ordered by kind (parallel, coaxial, orthogonal,
/// equal_radius, coplanar, tangent), then by their clusters.
/// Throws InvalidInputError when the segmentation or the reports do not match the hierarchy.
std::vector<ClusterRelation> regularize_clusters(const Hierarchy& hierarchy,
                                                 const Segmentation& segmentation,
                                                 std::vector<ClusterReport>& reports,
                                                 const RelationOptions& options = {});

/// One level of LevelRegularizer: its clusters and relations, as cut_by_count(),
/// describe_clusters() and regularize_clusters() give them.
struct RegularizedLevel {
  std::vector<std::uint32_t> nodes;    ///< tree node of each cluster label, shape (K)
  std::vector<ClusterReport> reports;  ///< shape (K); members of a relation refitted
  std::vector<ClusterRelation> relations;
};

/// The relations of many levels of one hierarchy, each what regularize_clusters() finds on
/// cut_by_count()'s level with describe_clusters()' reports, bit for bit: for browsing the
/// relations level by level (`primseg view --regularize`). regularize_clusters() gathers every
/// cluster's vertices and inliers from all F faces at each level; this gathers each node's once,
/// so that a level costs its regularization alone (bunny00's 391 levels: see docs/method.md).
class LevelRegularizer {
 public:
  /// `nodes` (strictly increasing) must hold every cluster of the levels asked for, and
  /// `reports` are their describe_nodes() reports, in the same order; `hierarchy` must outlive
  /// this. Gathers each node's vertices and inliers on `threads` threads (0: all cores):
  /// O(Σ node sizes) time and memory.
  /// Throws InvalidInputError when a node is not one describe_nodes() reports, the nodes are not
  /// increasing or the sizes differ, or for options out of range.
  LevelRegularizer(const Hierarchy& hierarchy, std::span<const std::uint32_t> nodes,
                   std::span<const ClusterReport> reports, const RelationOptions& options = {},
                   unsigned threads = 0);

  /// The level of `clusters` clusters (cut_by_count()'s: the component count at least): its
  /// nodes by label, their reports (`id` the label) and its relations, refitted members
  /// measured as describe_clusters() measures. O(K log K + the members' regularization and
  /// measure). Safe to call from several threads at once. Throws InvalidInputError when a
  /// cluster of the level is not among the constructor's nodes, or `clusters` is 0 or above F.
  RegularizedLevel level(std::uint32_t clusters) const;

  ~LevelRegularizer();
  LevelRegularizer(LevelRegularizer&&) noexcept;
  LevelRegularizer& operator=(LevelRegularizer&&) noexcept;

 private:
  struct Nodes;  // each node's triangles, inliers and measures
  const Hierarchy* hierarchy_;
  RelationOptions options_;
  std::unique_ptr<Nodes> nodes_;
};

}  // namespace primseg
