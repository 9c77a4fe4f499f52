#pragma once
// The larger eigenvalue of a symmetric 2x2 matrix in closed form.
//
// Eigen's SelfAdjointEigenSolver gives the same to round-off of the norm, but instantiating it for
// a 2x2 matrix (tridiagonalisation, implicit QR and the dynamic-size code they reach) took a third
// of regularity/directions.cpp's compile time (g++ -O3: 44 s with it, 26 s without; session 58).

#include <Eigen/Core>
#include <cmath>

namespace primseg::detail {

/// The larger eigenvalue of the symmetric matrix a, read from its lower triangle as Eigen's
/// solvers read it: the mean of the diagonal plus the hypotenuse of half its difference and the
/// off-diagonal entry. Accurate to a few ulps of the matrix's norm; not finite when an entry read
/// is not.
inline double larger_eigenvalue(const Eigen::Matrix2d& a) {
  const double mean = 0.5 * (a(0, 0) + a(1, 1));
  const double half_gap = 0.5 * (a(0, 0) - a(1, 1));
  return mean + std::hypot(half_gap, a(1, 0));
}

}  // namespace primseg::detail
