#include "primitives/pratt_fit.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace primseg::detail {

template <int D>
PrattResult<D> pratt_fit(const CentredMomentsND<D>& moments) {
  using Vector = Eigen::Matrix<double, D, 1>;
  using Matrix = Eigen::Matrix<double, D, D>;
  PrattResult<D> result;
  const double w = moments.weight;
  const double spread2 = moments.second.trace() / w;
  if (!(w > 0) || !(spread2 > 0) || !std::isfinite(spread2)) return result;

  // Scale the points to unit RMS spread so that every quantity below is of order w.
  const double scale = 1 / std::sqrt(spread2);
  const double scale2 = scale * scale;
  const double f = moments.fourth * scale2 * scale2;  // Σ w |p|⁴
  const Vector t = moments.third * (scale2 * scale);  // Σ w p |p|²
  const Matrix c = moments.second * scale2;           // Σ w p pᵀ
  const double s = c.trace();                         // Σ w |p|²

  // With θ = (A, B, C) and centred points, the rows of (M − ηN) θ = 0 give
  //   C = −(s + 2η) A / w,   B = −(c − ηI)⁻¹ t A,
  // and A ≠ 0 solves the secular equation
  //   g(η) = f − (s + 2η)² / w − Σ_k τ_k² / (λ_k − η) = 0,   τ = Uᵀ t,  c = U Λ Uᵀ.
  // On [0, λ_min) g is strictly decreasing with g(0) ≥ 0 (a Schur complement of the positive
  // semi-definite M), so the smallest η ≥ 0 is its only root there. No root before λ_min means
  // the optimum is the plane limit (A = 0): not a sphere.
  Eigen::SelfAdjointEigenSolver<Matrix> eigen(c);
  const Vector lambda = eigen.eigenvalues();
  const Vector tau = eigen.eigenvectors().transpose() * t;
  auto g = [&](double eta, double* derivative) {
    double value = f - (s + 2 * eta) * (s + 2 * eta) / w;
    double slope = -4 * (s + 2 * eta) / w;
    for (int k = 0; k < D; ++k) {
      const double gap = lambda(k) - eta;
      value -= tau(k) * tau(k) / gap;
      slope -= tau(k) * tau(k) / (gap * gap);
    }
    *derivative = slope;
    return value;
  };
  double lo = 0, hi = lambda(0);
  if (!(hi > 0)) return result;  // flat data: the plane itself
  double eta = 0, slope = 0;
  double value = g(eta, &slope);
  if (!(value > 0)) {
    eta = 0;  // an exact fit (round-off can make g(0) a hair negative)
  } else {
    for (int iteration = 0; iteration < 200; ++iteration) {
      if (value > 0)
        lo = eta;
      else
        hi = eta;
      // Newton while it stays inside the bracket, bisection otherwise.
      double next = eta - value / slope;
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (!(std::abs(next - eta) > 1e-15 * std::max(hi, 1e-300))) break;
      eta = next;
      value = g(eta, &slope);
      if (value == 0) break;
    }
  }
  result.objective_minimum = std::max(0.0, eta) / scale2;
  const double gap_to_plane = lambda(0) - eta;
  if (!(gap_to_plane > 1e-12 * lambda(D - 1))) return result;

  Vector b = Vector::Zero();
  for (int k = 0; k < D; ++k) b -= eigen.eigenvectors().col(k) * (tau(k) / (lambda(k) - eta));
  // With A = 1: centre −B/2, r² = (|B|² − 4C) / 4 = |B|²/4 + (s + 2η)/w.
  const double relative_radius = std::sqrt(b.squaredNorm() / 4 + (s + 2 * eta) / w);
  if (!(relative_radius <= kMaxRelativeRadius)) return result;
  result.valid = true;
  result.error = std::max(0.0, eta) / scale2;
  result.centre = -b / 2 / scale;
  result.radius = relative_radius / scale;
  return result;
}

template PrattResult<2> pratt_fit<2>(const CentredMomentsND<2>&);
template PrattResult<3> pratt_fit<3>(const CentredMomentsND<3>&);

}  // namespace primseg::detail
