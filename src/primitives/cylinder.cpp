// Cylinder: the axis is the eigenvector of the largest-magnitude eigenvalue of the normal-variation
// tensor Σ |e| β(e) ê êᵀ (edges along the generators bend, edges across them do not; for a hole
// every β is negative, hence the magnitude), then Pratt's circle fit of the points projected on
// the plane orthogonal to the axis. Every 2D moment it needs is a contraction of the 3D moments
// with P (the plane's basis) and Q = I − a aᵀ, so the fit costs the same for any cluster size.
// Its error is the circle's Σ w (|p − c|² − r²)² / (4r²), first-order in the distance.
#include "primseg/primitives/cylinder.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>

#include "primitives/pratt_fit.hpp"

namespace primseg {
namespace {

// An axis needs real bending: |λ| against the cluster's size (both lengths; β is an angle).
constexpr double kMinRelativeAxisEigenvalue = 1e-9;

}  // namespace

std::uint32_t CylinderFitter::min_triangles() const {
  return 4;
}

PrimitiveFit CylinderFitter::fit(const ClusterStats& centred) const {
  PrimitiveFit result;
  result.primitive.type = PrimitiveType::Cylinder;
  if (centred.triangle_count < min_triangles() || !(centred.area > 0)) return result;

  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(centred.edges.tensor_matrix());
  const Eigen::Vector3d lambda = solver.eigenvalues();
  const int largest = std::abs(lambda(0)) > std::abs(lambda(2)) ? 0 : 2;
  if (!(std::abs(lambda(largest)) > kMinRelativeAxisEigenvalue * std::sqrt(centred.area)))
    return result;
  const Eigen::Vector3d axis = canonical_axis(solver.eigenvectors().col(largest).normalized());

  // Orthonormal basis (u, v) of the plane orthogonal to the axis.
  Eigen::Index least_aligned;
  axis.cwiseAbs().minCoeff(&least_aligned);
  const Eigen::Vector3d u = axis.cross(Eigen::Vector3d::Unit(least_aligned)).normalized();
  const Eigen::Vector3d v = axis.cross(u);
  Eigen::Matrix<double, 2, 3> basis;
  basis.row(0) = u.transpose();
  basis.row(1) = v.transpose();
  const Eigen::Matrix3d projector = Eigen::Matrix3d::Identity() - axis * axis.transpose();

  const Moments& m = centred.moments;
  detail::CentredMomentsND<2> moments;
  moments.weight = m.weight();
  moments.second = basis * m.second_moment() * basis.transpose();
  moments.third = basis * m.third_moment_contracted(projector);
  moments.fourth = m.fourth_moment_contracted(projector);
  const detail::PrattResult<2> circle = detail::pratt_fit(moments);
  if (!circle.valid) return result;

  const Eigen::Vector3d point = m.origin() + basis.transpose() * circle.centre;
  result.normal_alignment = centred.normal_alignment(projector, point, circle.radius);
  if (result.normal_alignment < kMinNormalAlignment) return result;
  result.valid = true;
  result.error = circle.error;
  result.primitive.point = {point.x(), point.y(), point.z()};
  result.primitive.axis = {axis.x(), axis.y(), axis.z()};
  result.primitive.radius = circle.radius;
  return result;
}

}  // namespace primseg
