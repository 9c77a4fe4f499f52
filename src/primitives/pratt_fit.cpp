#include "primitives/pratt_fit.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace primseg::detail {

template <int D>
PrattResult<D> pratt_fit(const CentredMomentsND<D>& moments) {
  constexpr int n = D + 2;
  using Matrix = Eigen::Matrix<double, n, n>;
  PrattResult<D> result;
  const double spread2 = moments.second.trace() / moments.weight;
  if (!(moments.weight > 0) || !(spread2 > 0) || !std::isfinite(spread2)) return result;

  // Scale the points to unit RMS spread so that the matrix entries are of comparable size.
  const double s = 1 / std::sqrt(spread2);
  const double s2 = s * s;
  Matrix m = Matrix::Zero();
  m(0, 0) = moments.fourth * s2 * s2;
  m.template block<1, D>(0, 1) = (moments.third * s2 * s).transpose();
  m(0, n - 1) = moments.second.trace() * s2;
  m.template block<D, D>(1, 1) = moments.second * s2;
  m(n - 1, n - 1) = moments.weight;
  m.template block<D, 1>(1, 0) = m.template block<1, D>(0, 1).transpose();
  m(n - 1, 0) = m(0, n - 1);

  Matrix constraint = Matrix::Zero();
  constraint(0, n - 1) = constraint(n - 1, 0) = -2;
  for (int a = 1; a <= D; ++a) constraint(a, a) = 1;

  // M θ = η N θ, i.e. η is an eigenvalue of N⁻¹M; the fit is the smallest η whose eigenvector
  // is a real sphere (θᵀNθ > 0; the one negative η has θᵀNθ < 0). N⁻¹M swaps and scales the A
  // and C rows of M. Not the symmetric-definite route: an exact fit makes M singular, and a
  // Cholesky factor of a singular M is garbage.
  Matrix reduced = m;
  reduced.row(0) = -0.5 * m.row(n - 1);
  reduced.row(n - 1) = -0.5 * m.row(0);
  Eigen::EigenSolver<Matrix> solver(reduced, true);
  if (solver.info() != Eigen::Success) return result;
  int best = -1;
  double best_eta = 0, norm = 0;
  Eigen::Matrix<double, n, 1> theta;
  for (int k = 0; k < n; ++k) {
    const Eigen::Matrix<double, n, 1> candidate = solver.eigenvectors().col(k).real();
    const double candidate_norm = candidate.dot(constraint * candidate);
    if (!(candidate_norm > 0)) continue;
    const double eta = solver.eigenvalues()(k).real();
    if (best < 0 || eta < best_eta) {
      best = k;
      best_eta = eta;
      norm = candidate_norm;
      theta = candidate;
    }
  }
  if (best < 0) return result;
  const double a = theta(0);
  const Eigen::Matrix<double, D, 1> b = theta.template segment<D>(1);
  // r² = (|B|² − 4AC) / (4A²) in scaled units.
  const double relative_radius = std::sqrt(norm) / (2 * std::abs(a));
  if (!(relative_radius <= kMaxRelativeRadius)) return result;

  result.valid = true;
  result.error = std::max(0.0, theta.dot(m * theta) / norm) / s2;
  result.centre = -b / (2 * a) / s;
  result.radius = relative_radius / s;
  return result;
}

template PrattResult<2> pratt_fit<2>(const CentredMomentsND<2>&);
template PrattResult<3> pratt_fit<3>(const CentredMomentsND<3>&);

}  // namespace primseg::detail
