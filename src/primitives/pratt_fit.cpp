#include "primitives/pratt_fit.hpp"

#include <algorithm>
#include <cmath>

#include "primseg/cluster_view.hpp"
#include "symmetric_eigen3.hpp"

namespace primseg::detail {
namespace {

template <int D>
struct Eigensystem {
  Eigen::Matrix<double, D, 1> values;  // ascending
  Eigen::Matrix<double, D, D> vectors;
};

Eigensystem<2> eigensystem_of(const Eigen::Matrix2d& c) {
  // One Jacobi rotation: tan 2θ = 2 c01 / (c00 − c11), |θ| <= π/4, exact for any gap.
  double cosine = 1, sine = 0;
  if (c(0, 1) != 0) {
    const double zeta = (c(1, 1) - c(0, 0)) / (2 * c(0, 1));
    const double tangent = (zeta >= 0 ? 1.0 : -1.0) / (std::abs(zeta) + std::sqrt(1 + zeta * zeta));
    cosine = 1 / std::sqrt(1 + tangent * tangent);
    sine = tangent * cosine;
  }
  Eigensystem<2> e;
  e.vectors << cosine, sine, -sine, cosine;
  for (int k = 0; k < 2; ++k) e.values(k) = e.vectors.col(k).dot(c * e.vectors.col(k));
  if (e.values(0) > e.values(1)) {
    std::swap(e.values(0), e.values(1));
    e.vectors.col(0).swap(e.vectors.col(1));
  }
  return e;
}

Eigensystem<3> eigensystem_of(const Eigen::Matrix3d& c) {
  const SymmetricEigen3 e = symmetric_eigen3(c);
  return {e.values, e.vectors};
}

double smallest_eigenvalue_of(const Eigen::Matrix2d& c) {
  const double half_gap = 0.5 * (c(0, 0) - c(1, 1));
  return 0.5 * (c(0, 0) + c(1, 1)) - std::sqrt(half_gap * half_gap + c(0, 1) * c(0, 1));
}

double smallest_eigenvalue_of(const Eigen::Matrix3d& c) {
  return smallest_eigenpair(c).value;
}

// t·adj(M) t and det M for a symmetric M (t·M⁻¹t times det M, with no division).
double adjugate_form(const Eigen::Matrix2d& m, const Eigen::Vector2d& t, double* det) {
  *det = m(0, 0) * m(1, 1) - m(0, 1) * m(0, 1);
  return m(1, 1) * t(0) * t(0) + m(0, 0) * t(1) * t(1) - 2 * m(0, 1) * t(0) * t(1);
}

double adjugate_form(const Eigen::Matrix3d& m, const Eigen::Vector3d& t, double* det) {
  const double a00 = m(1, 1) * m(2, 2) - m(1, 2) * m(1, 2);
  const double a11 = m(0, 0) * m(2, 2) - m(0, 2) * m(0, 2);
  const double a22 = m(0, 0) * m(1, 1) - m(0, 1) * m(0, 1);
  const double a01 = m(0, 2) * m(1, 2) - m(0, 1) * m(2, 2);
  const double a02 = m(0, 1) * m(1, 2) - m(0, 2) * m(1, 1);
  const double a12 = m(0, 1) * m(0, 2) - m(0, 0) * m(1, 2);
  *det = m(0, 0) * a00 + m(0, 1) * a01 + m(0, 2) * a02;
  return a00 * t(0) * t(0) + a11 * t(1) * t(1) + a22 * t(2) * t(2) +
         2 * (a01 * t(0) * t(1) + a02 * t(0) * t(2) + a12 * t(1) * t(2));
}

// Whether the secular function g (pratt_fit()) is non-negative at x, for x below the smallest
// eigenvalue of c: then c − xI is positive definite and g(x) det(c − xI) = (f − (s + 2x)²/w) det
// − t·adj(c − xI) t, with no eigen-decomposition and no division.
template <int D>
bool secular_non_negative_at(const Eigen::Matrix<double, D, D>& c,
                             const Eigen::Matrix<double, D, 1>& t, double f, double s, double w,
                             double x) {
  const Eigen::Matrix<double, D, D> shifted = c - Eigen::Matrix<double, D, D>::Identity() * x;
  double det = 0;
  const double form = adjugate_form(shifted, t, &det);
  return (f - (s + 2 * x) * (s + 2 * x) / w) * det - form >= 0;
}

// The secular equation of pratt_fit() in the eigenbasis of c (eigenvalues λ ascending, τ = Uᵀ t)
// as h(η) = (λ_0 − η) g(η), which has the same root on [0, λ_0) but no pole at λ_0 (Newton's
// method on g itself keeps overshooting into the pole, and bisecting back, when the root is near
// it).
template <int D>
struct SecularEquation {
  Eigen::Matrix<double, D, 1> lambda, tau;
  double f = 0, s = 0, w = 0;

  double h(double eta, double* derivative) const {
    double rest = f - (s + 2 * eta) * (s + 2 * eta) / w;
    double rest_slope = -4 * (s + 2 * eta) / w;
    for (int k = 1; k < D; ++k) {
      const double gap = lambda(k) - eta;
      rest -= tau(k) * tau(k) / gap;
      rest_slope -= tau(k) * tau(k) / (gap * gap);
    }
    const double gap = lambda(0) - eta;
    *derivative = gap * rest_slope - rest;
    return gap * rest - tau(0) * tau(0);
  }

  // The root on [0, λ_0) (λ_0 > 0): Newton's method while it stays inside the bracket, bisection
  // otherwise; 0 for an exact fit (round-off can make g(0) a hair negative).
  double root() const {
    double lo = 0, hi = lambda(0);
    // Steps below this are round-off. (Relative to the whole bracket: relative to a shrinking
    // one, a root at the round-off level of 0 would take every iteration bisecting towards it.)
    const double resolution = 1e-15 * hi;
    double eta = 0, slope = 0;
    double value = h(eta, &slope);
    if (!(value > 0)) return 0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      if (value > 0)
        lo = eta;
      else
        hi = eta;
      double next = eta - value / slope;
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (!(std::abs(next - eta) > resolution)) break;
      eta = next;
      value = h(eta, &slope);
      if (value == 0) break;
    }
    return eta;
  }
};

// pratt_fit(), with the eigen-decomposition of moments.second from eigensystem_of_second(),
// asked for only when the fit needs it.
template <int D, class EigensystemSource>
PrattResult<D> fit(const CentredMomentsND<D>& moments, double objective_to_beat,
                   double smallest_eigenvalue, EigensystemSource eigensystem_of_second) {
  using Vector = Eigen::Matrix<double, D, 1>;
  PrattResult<D> result;
  const double w = moments.weight;
  const double spread2 = moments.second.trace() / w;
  if (!(w > 0) || !(spread2 > 0) || !std::isfinite(spread2)) return result;

  // Scale the points to unit RMS spread so that every quantity below is of order w.
  const double scale = 1 / std::sqrt(spread2);
  const double scale2 = scale * scale;
  const double f = moments.fourth * scale2 * scale2;  // Σ w |p|⁴
  const Vector t = moments.third * (scale2 * scale);  // Σ w p |p|²
  const double s = moments.second.trace() * scale2;   // Σ w |p|²

  // With θ = (A, B, C) and centred points, the rows of (M − ηN) θ = 0 give
  //   C = −(s + 2η) A / w,   B = −(c − ηI)⁻¹ t A,
  // and A ≠ 0 solves the secular equation
  //   g(η) = f − (s + 2η)² / w − Σ_k τ_k² / (λ_k − η) = 0,   τ = Uᵀ t,  c = U Λ Uᵀ,
  // with c = Σ w p pᵀ of the scaled points. On [0, λ_min) g is strictly decreasing with
  // g(0) ≥ 0 (a Schur complement of the positive semi-definite M), so the smallest η ≥ 0 is its
  // only root there. No root before λ_min means the optimum is the plane limit (A = 0): not a
  // sphere.
  if (std::isnan(smallest_eigenvalue)) smallest_eigenvalue = smallest_eigenvalue_of(moments.second);
  const double lambda_min = smallest_eigenvalue * scale2;
  if (!(lambda_min > 0)) return result;  // flat data: the plane itself
  // g decreases: the root is at least x exactly when g(x) >= 0.
  const double beat = objective_to_beat * scale2;
  if (beat > 0 && beat < lambda_min &&
      secular_non_negative_at<D>(moments.second * scale2, t, f, s, w, beat)) {
    result.beaten = true;
    result.objective_minimum = objective_to_beat;
    return result;
  }

  const auto& second = eigensystem_of_second();  // (values ascending, vectors as columns)
  const SecularEquation<D> secular{second.values * scale2, second.vectors.transpose() * t, f, s, w};
  const Vector& lambda = secular.lambda;
  const Vector& tau = secular.tau;
  if (!(lambda(0) > 0)) return result;  // round-off: flat data after all
  const double eta = secular.root();
  result.objective_minimum = std::max(0.0, eta) / scale2;
  const double gap_to_plane = lambda(0) - eta;
  if (!(gap_to_plane > 1e-12 * lambda(D - 1))) return result;

  Vector b = Vector::Zero();
  for (int k = 0; k < D; ++k) b -= second.vectors.col(k) * (tau(k) / (lambda(k) - eta));
  // With A = 1: centre −B/2, r² = (|B|² − 4C) / 4 = |B|²/4 + (s + 2η)/w.
  const double relative_radius = std::sqrt(b.squaredNorm() / 4 + (s + 2 * eta) / w);
  if (!(relative_radius <= kMaxRelativeRadius)) return result;
  result.valid = true;
  result.error = std::max(0.0, eta) / scale2;
  result.centre = -b / 2 / scale;
  result.radius = relative_radius / scale;
  return result;
}

}  // namespace

template <int D>
PrattResult<D> pratt_fit(const CentredMomentsND<D>& moments, double objective_to_beat,
                         double smallest_eigenvalue) {
  return fit(moments, objective_to_beat, smallest_eigenvalue,
             [&] { return eigensystem_of(moments.second); });
}

PrattResult<3> pratt_fit(const ClusterView& cluster, double objective_to_beat) {
  const ClusterView::RadialMoments& radial = cluster.radial_moments();
  CentredMomentsND<3> moments;
  moments.weight = cluster.weight();
  moments.second = cluster.second_moment();
  moments.third = radial.third;
  moments.fourth = radial.fourth;
  return fit(
      moments, objective_to_beat, cluster.smallest_eigenvalue(),
      [&]() -> const ClusterView::Eigensystem& { return cluster.second_moment_eigensystem(); });
}

template PrattResult<2> pratt_fit<2>(const CentredMomentsND<2>&, double, double);
template PrattResult<3> pratt_fit<3>(const CentredMomentsND<3>&, double, double);

}  // namespace primseg::detail
