#pragma once
// Eigen-decomposition of a symmetric 3x3 matrix in closed form, for the merge loop's fits.
//
// Eigen's iterative solver (tridiagonalisation and implicit QR) takes about 235 ns for a 3x3
// matrix; its closed-form computeDirect() about 150 ns but its smallest eigenvalue can be off by
// 3e-13 of the trace, which is the whole cost of a nearly flat cluster. This one is as accurate as
// the iterative solver (eigenvalues within a few ulps of the matrix's norm) at about a third of
// its time:
//  1. the eigenvalue farthest from the middle one, by Newton's method on the characteristic cubic
//     (scaled and shifted by the mean eigenvalue): its gap to the others is at least half their
//     spread, so it is a simple root where Newton converges fast;
//  2. its eigenvector, as the largest cross product of two rows of (A − λI);
//  3. the other two from the 2x2 problem in the plane orthogonal to it, solved by one Jacobi
//     rotation, which is exact even when those two eigenvalues are close;
//  4. every eigenvalue recomputed as the Rayleigh quotient of its vector, which removes the
//     cubic's round-off (quadratic in the vector's error).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>


namespace primseg::detail {

/// Eigenvalues in ascending order and orthonormal eigenvectors (columns, same order).
struct SymmetricEigen3 {
  Eigen::Vector3d values;
  Eigen::Matrix3d vectors;
};

namespace eigen3_detail {

// A unit vector orthogonal to the unit vector v.
inline Eigen::Vector3d any_orthogonal(const Eigen::Vector3d& v) {
  // Cross with the axis v is least aligned with: |v × e| >= sqrt(2/3).
  const Eigen::Vector3d a = v.cwiseAbs();
  const Eigen::Vector3d e = a.x() <= a.y() && a.x() <= a.z()   ? Eigen::Vector3d::UnitX()
                            : a.y() <= a.z()                   ? Eigen::Vector3d::UnitY()
                                                               : Eigen::Vector3d::UnitZ();
  return v.cross(e).normalized();
}

// Unit eigenvector of the symmetric b for its simple eigenvalue mu: the largest of the cross
// products of two rows of b − mu I (all three are parallel to it). Falls back to any unit
// vector when b − mu I has rank below 2 (mu not simple: every vector of its space will do).
inline Eigen::Vector3d eigenvector_of(const Eigen::Matrix3d& b, double mu) {
  const Eigen::Vector3d r0(b(0, 0) - mu, b(0, 1), b(0, 2));
  const Eigen::Vector3d r1(b(1, 0), b(1, 1) - mu, b(1, 2));
  const Eigen::Vector3d r2(b(2, 0), b(2, 1), b(2, 2) - mu);
  const Eigen::Vector3d c01 = r0.cross(r1), c02 = r0.cross(r2), c12 = r1.cross(r2);
  const double n01 = c01.squaredNorm(), n02 = c02.squaredNorm(), n12 = c12.squaredNorm();
  if (n01 >= n02 && n01 >= n12 && n01 > 0) return c01 / std::sqrt(n01);
  if (n02 >= n12 && n02 > 0) return c02 / std::sqrt(n02);
  if (n12 > 0) return c12 / std::sqrt(n12);
  // Rank below 2: a row that is not zero is orthogonal to the eigenspace's complement.
  for (const Eigen::Vector3d* r : {&r0, &r1, &r2})
    if (r->squaredNorm() > 0) return any_orthogonal(r->normalized());
  return Eigen::Vector3d::UnitX();
}

}  // namespace eigen3_detail

/// Eigen-decomposition of the symmetric matrix a. Input with a non-finite entry gives NaN
/// eigenvalues.
inline SymmetricEigen3 symmetric_eigen3(const Eigen::Matrix3d& a) {
  using eigen3_detail::eigenvector_of;
  SymmetricEigen3 result;
  result.vectors = Eigen::Matrix3d::Identity();
  const double scale = a.cwiseAbs().maxCoeff();
  if (!std::isfinite(scale)) {
    result.values = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    return result;
  }
  if (scale == 0) {
    result.values = Eigen::Vector3d::Zero();  // every vector is an eigenvector
    return result;
  }
  // Scaled to entries of magnitude at most 1, shifted by the mean eigenvalue.
  Eigen::Matrix3d b = a / scale;
  const double mean = b.trace() / 3;
  b.diagonal().array() -= mean;
  const double off = b(0, 1) * b(0, 1) + b(0, 2) * b(0, 2) + b(1, 2) * b(1, 2);
  const double p2 = (b(0, 0) * b(0, 0) + b(1, 1) * b(1, 1) + b(2, 2) * b(2, 2) + 2 * off) / 6;
  if (!(p2 > 0)) {
    // A multiple of the identity.
    result.values = Eigen::Vector3d::Constant(a(0, 0));
    return result;
  }
  const double p = std::sqrt(p2);
  const double det = b(0, 0) * (b(1, 1) * b(2, 2) - b(1, 2) * b(1, 2)) -
                     b(0, 1) * (b(0, 1) * b(2, 2) - b(1, 2) * b(0, 2)) +
                     b(0, 2) * (b(0, 1) * b(1, 2) - b(1, 1) * b(0, 2));
  // The eigenvalues of b are 2p x for the three roots x of 4x³ − 3x = r (cos 3θ = r). For r >= 0
  // the largest root, in [√3/2, 1], is farthest from the middle one; for r < 0 the smallest,
  // by symmetry. Only that isolated root is needed: Newton's method from a quadratic fit of it in
  // 1 − |r| (exact at |r| = 1, within 1.1e-3 elsewhere) descends on the convex cubic, to within
  // 1e-11 after two steps and round-off after three. (The Rayleigh quotients below are then exact
  // to second order in that error.)
  const double r = std::clamp(det / (2 * p2 * p), -1.0, 1.0);
  const bool low_isolated = r < 0;
  const double abs_r = std::abs(r);
  const double t = 1 - abs_r;
  double x = 1 - t * (1.0 / 9 + 0.0229 * t);
  for (int step = 0; step < 3; ++step) x -= (x * (4 * x * x - 3) - abs_r) / (12 * x * x - 3);
  const Eigen::Vector3d first = eigenvector_of(b, 2 * p * (low_isolated ? -x : x));
  // The 2x2 problem in the plane orthogonal to it: basis (u, v), matrix [[buu, buv], [buv, bvv]].
  const Eigen::Vector3d u = eigen3_detail::any_orthogonal(first);
  const Eigen::Vector3d v = first.cross(u);
  const Eigen::Vector3d bu = b * u, bv = b * v;
  const double buu = u.dot(bu), bvv = v.dot(bv), buv = u.dot(bv);
  // One Jacobi rotation (c, s) diagonalises it: tan 2θ = 2 buv / (buu − bvv), |θ| <= π/4.
  double c = 1, s = 0;
  if (buv != 0) {
    const double zeta = (bvv - buu) / (2 * buv);
    const double tangent =
        (zeta >= 0 ? 1.0 : -1.0) / (std::abs(zeta) + std::sqrt(1 + zeta * zeta));
    c = 1 / std::sqrt(1 + tangent * tangent);
    s = tangent * c;
  }
  result.vectors.col(0) = first;
  result.vectors.col(1) = c * u - s * v;
  result.vectors.col(2) = s * u + c * v;
  // Rayleigh quotients of the unscaled, unshifted matrix, then ascending order.
  for (int k = 0; k < 3; ++k)
    result.values(k) = result.vectors.col(k).dot(a * result.vectors.col(k));
  auto order = [&](int i, int j) {
    if (result.values(i) > result.values(j)) {
      std::swap(result.values(i), result.values(j));
      result.vectors.col(i).swap(result.vectors.col(j));
    }
  };
  order(0, 1);
  order(1, 2);
  order(0, 1);
  return result;
}

}  // namespace primseg::detail
