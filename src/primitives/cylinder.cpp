// Cylinder: the axis is the eigenvector of the largest-magnitude eigenvalue of the normal-variation
// tensor Σ |e| β(e) ê êᵀ (edges along the generators bend, edges across them do not; for a hole
// every β is negative, hence the magnitude), then Pratt's circle fit of the points projected on
// the plane orthogonal to the axis. Every 2D moment it needs is a contraction of the 3D moments
// with P (the plane's basis) and Q = I − a aᵀ, so the fit costs the same for any cluster size.
// Its error is the circle's Σ w (|p − c|² − r²)² / (4r²), first-order in the distance.
#include "primseg/primitives/cylinder.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "orthonormal_pair.hpp"
#include "primitives/pratt_fit.hpp"
#include "symmetric_eigen3.hpp"

namespace primseg {
namespace {

// An axis needs real bending: |λ| against the cluster's size (both lengths; β is an angle).
constexpr double kMinRelativeAxisEigenvalue = 1e-9;

}  // namespace

std::uint32_t CylinderFitter::min_triangles() const {
  return 4;
}

PrimitiveFit CylinderFitter::fit(const ClusterView& cluster, double error_to_beat) const {
  PrimitiveFit result;
  result.primitive.type = PrimitiveType::Cylinder;
  if (cluster.triangle_count() < min_triangles() || !(cluster.area() > 0)) return result;

  // Every eigenvalue is at most 3 max |T_ij| in magnitude: flat clusters stop here.
  const Eigen::Matrix3d tensor = cluster.edge_tensor();
  const double min_eigenvalue = kMinRelativeAxisEigenvalue * std::sqrt(cluster.area());
  if (!(3 * tensor.cwiseAbs().maxCoeff() > min_eigenvalue)) return result;
  const detail::Eigenpair dominant = detail::dominant_eigenpair(tensor);
  if (!(std::abs(dominant.value) > min_eigenvalue)) return result;
  const Eigen::Vector3d axis = canonical_axis(dominant.vector);

  // Orthonormal basis (u, v) of the plane orthogonal to the axis.
  const auto [u, v] = detail::orthonormal_pair(axis);
  Eigen::Matrix<double, 2, 3> basis;
  basis.row(0) = u.transpose();
  basis.row(1) = v.transpose();

  // With Q = I − a aᵀ: Σ w y (yᵀQy) and Σ w (yᵀQy)² from the radial and axial moments.
  const ClusterView::RadialMoments& radial = cluster.radial_moments();
  const ClusterView::AxialMoments axial = cluster.axial_moments(axis);
  detail::CentredMomentsND<2> moments;
  moments.weight = cluster.weight();
  moments.second = basis * cluster.second_moment() * basis.transpose();
  moments.third = basis * (radial.third - axial.third);
  moments.fourth = radial.fourth - 2 * axial.mixed + axial.fourth;
  const detail::PrattResult<2> circle = detail::pratt_fit(moments, error_to_beat);
  result.beaten = circle.beaten;
  if (!circle.valid) return result;

  const Eigen::Vector3d point = cluster.centroid() + basis.transpose() * circle.centre;
  const Eigen::Matrix3d projector = Eigen::Matrix3d::Identity() - axis * axis.transpose();
  result.normal_alignment = cluster.normal_alignment(projector, point, circle.radius);
  if (result.normal_alignment < kMinNormalAlignment) return result;
  result.valid = true;
  result.error = circle.error;
  result.primitive.point = {point.x(), point.y(), point.z()};
  result.primitive.axis = {axis.x(), axis.y(), axis.z()};
  result.primitive.radius = circle.radius;
  return result;
}

}  // namespace primseg
