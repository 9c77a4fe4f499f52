#pragma once
/// @file cluster_view.hpp
/// What a primitive fitter reads of a cluster: its weighted moments about its centroid and the
/// contractions of them each fit needs. A view is either one cluster or the union of two disjoint
/// clusters; for a union, every quantity is combined from the two parts' centred moments in
/// constant time, without forming the union's 35 moments (what a merge candidate costs).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>

#include "primseg/cluster_stats.hpp"

namespace primseg {

/// One side of a ClusterView: a cluster's statistics centred at its centroid
/// (ClusterStats::centred()), or a face or a pair of faces by its corners (FaceCorners). Refers
/// to it: it must outlive the views made of it.
class ClusterPart {
 public:
  // Implicit, so that a view is made of either kind alike: ClusterView(stats, face, shared).
  ClusterPart(const ClusterStats& centred) : stats_(&centred) {}
  ClusterPart(const FaceCorners& face) : face_(&face) {}

  /// The statistics, or null for a face by its corners.
  const ClusterStats* stats() const { return stats_; }
  /// The face's corners, or null for statistics.
  const FaceCorners* face() const { return face_; }

  double weight() const { return stats_ ? stats_->moments.weight() : face_->weight; }
  const Eigen::Vector3d& centroid() const {
    return stats_ ? stats_->moments.origin() : face_->centroid;
  }
  /// Σ w y yᵀ about centroid(), shape (3, 3).
  Eigen::Matrix3d second_moment() const {
    return stats_ ? stats_->moments.second_moment() : face_->second_moment;
  }
  std::uint32_t triangle_count() const {
    return stats_ ? stats_->triangle_count : face_->triangle_count;
  }
  double area() const { return stats_ ? stats_->area : face_->area; }
  const Eigen::Vector3d& normal_sum() const {
    return stats_ ? stats_->normal_sum : face_->normal_sum;
  }
  const Eigen::Matrix3d& normal_position() const {
    return stats_ ? stats_->normal_position : face_->normal_position;
  }
  const EdgeStats& edges() const { return stats_ ? stats_->edges : face_->edges; }

 private:
  const ClusterStats* stats_ = nullptr;
  const FaceCorners* face_ = nullptr;
};

/// A cluster's statistics as the fitters read them. Points y are relative to centroid(), in the
/// working frame; Σ runs over the weighted triangle corners of the cluster.
///
/// The parts must outlive the view, have moments about their own centroids (origin = centroid;
/// ClusterStats::centred()) and, for a union, share no triangle.
class ClusterView {
 public:
  /// One cluster, with statistics centred at its centroid.
  explicit ClusterView(const ClusterStats& centred);
  /// Not from a temporary, which would die before the view (`ClusterView v(s.centred());`).
  explicit ClusterView(const ClusterStats&& centred) = delete;
  /// The union of two disjoint clusters (centred statistics or single faces' corners); `shared`
  /// holds the mesh edges between them.
  ClusterView(ClusterPart a, ClusterPart b, const EdgeStats& shared);

  /// Σ w.
  double weight() const { return weight_; }
  /// The weighted centroid (working frame).
  const Eigen::Vector3d& centroid() const { return centroid_; }
  /// Σ w y yᵀ, shape (3, 3).
  const Eigen::Matrix3d& second_moment() const { return second_moment_; }
  /// The smallest eigenvalue of second_moment() and a unit eigenvector of it (computed on first
  /// use, then kept): the plane's error and normal.
  double smallest_eigenvalue() const { return smallest_eigenpair().value; }
  const Eigen::Vector3d& smallest_eigenvector() const { return smallest_eigenpair().vector; }
  /// Eigenvalues in ascending order and unit eigenvectors (columns, in the same order).
  struct Eigensystem {
    Eigen::Vector3d values;
    Eigen::Matrix3d vectors;
  };
  /// The eigen-decomposition of second_moment() (computed on first use, then kept; it goes on
  /// from what smallest_eigenvalue() computed). Where two eigenvalues are equal to round-off, its
  /// first column may be the other one than smallest_eigenvector().
  const Eigensystem& second_moment_eigensystem() const;

  std::uint32_t triangle_count() const { return triangle_count_; }
  /// Σ triangle area.
  double area() const { return area_; }
  /// Σ area × unit normal (consistently oriented normals).
  const Eigen::Vector3d& normal_sum() const { return normal_sum_; }
  /// The normal-variation tensor Σ |e| β(e) ê êᵀ of the cluster's internal edges, shape (3, 3).
  Eigen::Matrix3d edge_tensor() const;

  /// Σ w y |y|² (shape 3) and Σ w |y|⁴: the radial moments a sphere fit needs.
  /// (No default member initialisers: std::optional<RadialMoments> below is instantiated inside
  /// this class, where clang would not yet see them and would find it not constructible.)
  struct RadialMoments {
    Eigen::Vector3d third;
    double fourth;
  };
  /// (Computed on first use, then kept.)
  const RadialMoments& radial_moments() const;

  /// For a unit axis a: Σ w y (a·y)² (shape 3), Σ w |y|² (a·y)² and Σ w (a·y)⁴: with the radial
  /// moments, what a fit in the plane orthogonal to a needs (Q = I − a aᵀ gives
  /// Σ w y (yᵀQy) = radial.third − third and Σ w (yᵀQy)² = radial.fourth − 2 mixed + fourth).
  struct AxialMoments {
    Eigen::Vector3d third = Eigen::Vector3d::Zero();
    double mixed = 0;
    double fourth = 0;
  };
  AxialMoments axial_moments(const Eigen::Vector3d& axis) const;

  /// ClusterStats::normal_alignment of the cluster: the area-weighted mean |n · ν| of the face
  /// normals against the field ν(x) = Q (x − point) / radius.
  double normal_alignment(const Eigen::Matrix3d& q, const Eigen::Vector3d& point,
                          double radius) const;

  /// The corner samples a sampled fit (the torus's) reads, one reservoir per stratum: a single
  /// cluster's own; for a union of two clusters with statistics, each part's own, so that a fit
  /// can sample both (a small part merged into a large one would otherwise be left out of the
  /// union's sample by chance); else the union's (stats().samples). The second entry is null
  /// when there is one stratum.
  std::array<const SampleReservoir*, 2> sample_strata() const;

  /// The cluster's whole statistics, centred at centroid() (for a union: formed on first use,
  /// then kept; the first moments are exactly zero).
  const ClusterStats& stats() const;
  /// The same, formed anew, with the moments up to max_degree only (2: those of degree 3 and 4
  /// are left zero; the others are the same, bit for bit, as stats()').
  ClusterStats stats(int max_degree) const;

 private:
  // The parts, with the shift from their centroid to the view's: y = y_part + shift.
  ClusterPart parts_[2];
  Eigen::Vector3d shifts_[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  int part_count_ = 0;
  const EdgeStats* shared_ = nullptr;

  double weight_ = 0;
  Eigen::Vector3d centroid_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second_moment_ = Eigen::Matrix3d::Zero();
  std::uint32_t triangle_count_ = 0;
  double area_ = 0;
  Eigen::Vector3d normal_sum_ = Eigen::Vector3d::Zero();

  struct Eigenpair {
    double value;
    Eigen::Vector3d vector;
  };
  mutable std::optional<Eigenpair> smallest_;
  // The vectors the smallest pair's solver found on the way (src/symmetric_eigen3.hpp), from
  // which the whole decomposition goes on: how many, the isolated eigenvalue's, the other.
  struct EigenSteps {
    int count = 0;
    Eigen::Vector3d isolated, orthogonal;
  };
  mutable EigenSteps eigen_steps_;
  mutable std::optional<Eigensystem> eigensystem_;
  mutable std::optional<RadialMoments> radial_;
  mutable std::optional<Eigen::Matrix3d> normal_position_;  // Σ (c − centroid)(A n)ᵀ
  mutable std::optional<ClusterStats> union_stats_;
  // (The check inline: most calls find the pair computed.)
  const Eigenpair& smallest_eigenpair() const {
    if (!smallest_) compute_smallest_eigenpair();
    return *smallest_;
  }
  void compute_smallest_eigenpair() const;
};

}  // namespace primseg
