#pragma once
/// @file cluster_stats.hpp
/// Additive summary statistics of a cluster of triangles, from which every primitive fit and its
/// error are computed in time independent of the cluster's size. Merging two clusters adds their
/// statistics.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace primseg {

/// Weighted moments Σ w (x − o)^α of a point set about an origin o, for every monomial x^α of
/// degree 0 to 4 in three variables (35 numbers).
///
/// Degree-4 moments about a far-away origin lose all precision for a small cluster, so each
/// cluster keeps its own origin (near its points) and moments are translated exactly (binomial
/// expansion) before being added.
class Moments {
 public:
  static constexpr int kCount = 35;

  Moments() = default;
  explicit Moments(const Eigen::Vector3d& origin) : origin_(origin) {}

  /// Index of monomial x^i y^j z^k (i + j + k <= 4) in values(): monomials by degree, then by
  /// decreasing exponent of x, then of y.
  static constexpr int index(int i, int j, int k) {
    const int d = i + j + k;
    return d * (d + 1) * (d + 2) / 6 + (d - i) * (d - i + 1) / 2 + (d - i - j);
  }

  const Eigen::Vector3d& origin() const { return origin_; }
  const std::array<double, kCount>& values() const { return values_; }
  double at(int i, int j, int k) const { return values_[index(i, j, k)]; }

  /// Σ w.
  double weight() const { return values_[0]; }
  /// Weighted mean of the points (the origin for zero weight).
  Eigen::Vector3d centroid() const;

  /// Adds the point x with weight w (to the moments up to max_degree: 2 or 4).
  void add_point(const Eigen::Vector3d& x, double w, int max_degree = 4) {
    add_offset(x - origin_, w, max_degree);
  }
  /// Adds the point origin() + d with weight w.
  void add_offset(const Eigen::Vector3d& d, double w, int max_degree = 4);
  /// Sets the first moments to zero: for moments about a centroid the caller computed, whose
  /// first moments are only round-off (the centroid then is the origin exactly).
  void discard_first_moments() { values_[1] = values_[2] = values_[3] = 0; }
  /// Number of monomials of degree at most 2 (the first entries of values()).
  static constexpr int kCountUpToDegree2 = 10;

  /// The same moments about another origin. With max_degree 2 only the moments up to degree 2
  /// are computed (28 of the 210 terms) and the others are left zero: enough for a plane.
  Moments translated(const Eigen::Vector3d& new_origin, int max_degree = 4) const;
  /// Adds other's moments (translated to this origin), up to max_degree (see translated()).
  Moments& add(const Moments& other, int max_degree = 4);
  Moments& operator+=(const Moments& other) { return add(other); }

  /// Σ w (x−o)(x−o)ᵀ, the second moment matrix about the origin.
  Eigen::Matrix3d second_moment() const;
  /// Σ w (x−o)_a (x−o)_b (x−o)_c contracted with a symmetric 3x3 Q over (b, c): a 3-vector.
  Eigen::Vector3d third_moment_contracted(const Eigen::Matrix3d& q) const;
  /// Σ w ((x−o)ᵀ Q (x−o))², the fourth moment contracted twice with a symmetric 3x3 Q.
  double fourth_moment_contracted(const Eigen::Matrix3d& q) const;

 private:
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  std::array<double, kCount> values_{};
};

/// Statistics of a set of mesh edges: those inside a cluster, or those between two clusters.
struct EdgeStats {
  /// Normal-variation tensor Σ |e| β(e) ê êᵀ as the upper triangle (xx, xy, xz, yy, yz, zz). β
  /// is the signed dihedral angle (positive where convex).
  std::array<double, 6> tensor{};

  /// Adds the edge vector e with dihedral angle beta (radians).
  void add_edge(const Eigen::Vector3d& e, double beta);
  EdgeStats& operator+=(const EdgeStats& other);
  Eigen::Matrix3d tensor_matrix() const;
};

/// Moments of the cluster's face planes, about an origin o (ClusterStats keeps them about
/// moments.origin()): with A a triangle's area, n its unit normal and c its centroid,
/// Σ A n nᵀ, Σ A n (n·(c − o)) and Σ A (n·(c − o))². The point a minimising
/// Σ A (n·(a − c))² (the point nearest every face plane: a cone's apex) solves
/// (Σ A n nᵀ)(a − o) = Σ A n (n·(c − o)). Translating them to another origin is exact.
struct FacePlaneStats {
  /// Σ A n nᵀ as the upper triangle (xx, xy, xz, yy, yz, zz).
  std::array<double, 6> normal_normal{};
  /// Σ A n (n·(c − o)).
  Eigen::Vector3d normal_offset = Eigen::Vector3d::Zero();
  /// Σ A (n·(c − o))².
  double offset_square = 0;

  /// Adds a triangle of area `area`, unit normal n and centroid at `centroid_offset` = c − o.
  void add_face(const Eigen::Vector3d& n, double area, const Eigen::Vector3d& centroid_offset);
  /// The same sums about o + shift.
  FacePlaneStats translated(const Eigen::Vector3d& shift) const;
  FacePlaneStats& operator+=(const FacePlaneStats& other);
  Eigen::Matrix3d normal_normal_matrix() const;
};

/// A triangle corner of a cluster with its face's unit normal and centroid: what the torus fit
/// uses, since no moment of bounded degree describes a torus (its algebraic distance has degree
/// 4, its square 8).
struct SurfaceSample {
  Eigen::Vector3d position;  ///< working frame
  Eigen::Vector3f normal;    ///< unit normal of the corner's triangle (consistently oriented)
  /// The triangle's centroid − position: where the face's normal is compared with the fitted
  /// surface's (at a corner, a coarse facet may touch a wrong surface with the right normal).
  Eigen::Vector3f to_centroid;
  double weight = 0;    ///< the corner's weight w
  double priority = 0;  ///< w / u, u in (0, 1] fixed per corner (see SampleReservoir)
};

/// A priority sample (Duffield, Lund and Thorup, 2007) of a cluster's weighted corners: the
/// kCapacity + 1 corners of highest priority w / u, where u is a pseudo-random number fixed per
/// corner (a hash of its index). The sample of a union is the best kCapacity + 1 of the union of
/// the samples, so merging is exact, associative and deterministic, and its size is bounded.
/// With τ the lowest kept priority, the other kCapacity corners with estimator weights
/// max(w, τ) give an unbiased estimate Σ max(w, τ) f(x) of Σ w f(x) over the whole cluster;
/// clusters of at most kCapacity corners are kept whole (τ = 0: exact sums).
struct SampleReservoir {
  static constexpr std::size_t kCapacity = 32;
  /// Descending priority, at most kCapacity + 1.
  std::vector<SurfaceSample> samples;

  /// Adds one corner (its priority already set).
  void add(const SurfaceSample& sample);
  /// Adds the samples of a disjoint cluster.
  void merge(const SampleReservoir& other);
  /// τ: the priority of the (kCapacity + 1)-th sample, 0 when the cluster is kept whole.
  double threshold() const { return threshold(kCapacity); }
  /// τ of the smaller sample made of the best `size` samples (the best k of a priority sample are
  /// a priority sample of size k): the priority of the (size + 1)-th, 0 when there is none.
  double threshold(std::size_t size) const {
    return size < samples.size() ? samples[size].priority : 0.0;
  }
  /// Number of samples of the estimate (at most kCapacity).
  std::size_t estimate_size() const { return std::min(samples.size(), kCapacity); }
  /// Estimator weight max(w, τ) of sample i < estimate_size().
  double estimator_weight(std::size_t i) const;
  /// The priority w / u of corner `corner_id` of weight w.
  static double priority_of(std::uint64_t corner_id, double weight);
};

/// A small cluster, one input face or a pair of adjacent faces of at most kMaxTriangles triangles
/// in all, by its weighted corners (working frame), for the merge loop: a candidate that unites a
/// cluster with a face or a pair reads these few corners directly, which costs far less than
/// forming their 35 moments and translating them (most candidates of a scan have a single face
/// on one side, and pairs are most of the merged clusters alive at once). The same quantities as
/// the cluster's ClusterStats, about its weighted centroid. Filled by DualGraph::face_corners and
/// unite(); it carries no samples (the torus reads ClusterStats).
struct FaceCorners {
  static constexpr std::uint32_t kMaxTriangles = 4;
  std::uint32_t triangle_count = 0;
  /// The weighted centroid of the corners (the first triangle's centroid if they weigh nothing).
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  /// Corner positions − centroid, three per triangle; the first 3 triangle_count are set.
  std::array<Eigen::Vector3d, std::size_t{3} * kMaxTriangles> offsets;
  /// Their weights w.
  std::array<double, std::size_t{3} * kMaxTriangles> weights{};
  /// Per triangle: area × unit normal (consistently oriented), area, and centroid − centroid.
  std::array<Eigen::Vector3d, kMaxTriangles> area_normals;
  std::array<double, kMaxTriangles> areas{};
  std::array<Eigen::Vector3d, kMaxTriangles> triangle_offsets;
  /// Σ w.
  double weight = 0;
  /// Σ w y yᵀ with y = corner − centroid, shape (3, 3).
  Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();
  /// As in ClusterStats, about the centroid.
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d normal_position = Eigen::Matrix3d::Zero();
  double area = 0;
  /// The mesh edges between the cluster's own triangles.
  EdgeStats edges;

  std::uint32_t corner_count() const { return 3 * triangle_count; }
  /// The union of two disjoint small clusters and the mesh edges between them into `united`,
  /// about their weighted centroid (as ClusterView places it). False, with `united` unspecified,
  /// when they have more than kMaxTriangles triangles in all.
  static bool unite(const FaceCorners& a, const FaceCorners& b, const EdgeStats& shared,
                    FaceCorners& united);
};

/// Everything a primitive fit needs to know about a cluster; all sums over its triangles, so the
/// statistics of a union are the sums of its parts (plus the tensor of the edges between them).
struct ClusterStats {
  /// Moments of the weighted triangle corners (working frame).
  Moments moments;
  /// The cluster's internal edges (between two of its triangles).
  EdgeStats edges;
  /// Σ over triangles of area × unit normal (consistently oriented), for orienting plane normals.
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  /// Σ over triangles of (centroid − moments.origin()) (area × unit normal)ᵀ: with normal_sum,
  /// it gives how well the face normals agree with a curved primitive's normal field.
  Eigen::Matrix3d normal_position = Eigen::Matrix3d::Zero();
  /// The face planes about moments.origin() (for the cone's apex).
  FacePlaneStats face_planes;
  /// Σ triangle area (working frame).
  double area = 0;
  /// Number of triangles (the fits' minimum support is counted in triangles).
  std::uint32_t triangle_count = 0;
  /// A bounded sample of the corners, kept only when a type that needs it (the torus) is
  /// enabled; empty otherwise.
  SampleReservoir samples;

  /// Adds other (which must not share triangles with this) and the edges between the two. With
  /// max_degree 2 the moments of degree 3 and 4 are left zero (see Moments::translated).
  void merge(const ClusterStats& other, const EdgeStats& shared_edges, int max_degree = 4);
  /// Adds a single face given by its corners (not sharing triangles with this), without the edges
  /// between the two; samples are not added. Moments up to max_degree, as merge().
  void add(const FaceCorners& face, int max_degree = 4);
  /// The same statistics about another origin (moments up to max_degree).
  ClusterStats translated(const Eigen::Vector3d& new_origin, int max_degree = 4) const;
  /// The same statistics about the centroid (what the fitters take).
  ClusterStats centred(int max_degree = 4) const {
    return translated(moments.centroid(), max_degree);
  }
  /// Area-weighted mean of |n · ν| over the triangles, where ν(x) = Q (x − point) / radius is the
  /// unit normal field of a sphere (Q = I) or cylinder (Q = I − a aᵀ) at the triangle centroids
  /// (first order). 1 when every face agrees with the surface, about cos(θ/2) for facets that
  /// span an angle θ, and near the area fraction of the agreeing faces for a mixed cluster.
  double normal_alignment(const Eigen::Matrix3d& q, const Eigen::Vector3d& point,
                          double radius) const;
};

}  // namespace primseg
