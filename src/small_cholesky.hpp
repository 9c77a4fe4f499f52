#pragma once
// Cholesky factorisation and solves for the small symmetric systems of the fits (at most 8×8,
// fixed or bounded size), written out: Eigen's LLT and LDLT run their blocked kernels through
// dynamic-size blocks even for a 6×6 matrix, which made the damped solves of the cone's and the
// geometric fits' Levenberg–Marquardt steps a seventh of a cone-enabled hierarchy's time. Eigen's
// LDLᵀ remains the fallback for matrices that are not positive definite (solve_symmetric).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>

namespace primseg::detail {

/// The lower-triangular L with L Lᵀ = A, reading A's lower triangle. False, with `l`
/// unspecified, when A is not positive definite (a pivot is not positive, or not finite).
template <typename Matrix>
bool cholesky_factor(const Matrix& a, Matrix& l) {
  const Eigen::Index n = a.rows();
  l.setZero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    double pivot = a(j, j);
    for (Eigen::Index k = 0; k < j; ++k) pivot -= l(j, k) * l(j, k);
    if (!(pivot > 0) || !std::isfinite(pivot)) return false;
    l(j, j) = std::sqrt(pivot);
    for (Eigen::Index i = j + 1; i < n; ++i) {
      double sum = a(i, j);
      for (Eigen::Index k = 0; k < j; ++k) sum -= l(i, k) * l(j, k);
      l(i, j) = sum / l(j, j);
    }
  }
  return true;
}

/// L⁻¹ B (forward substitution), column by column; B may be a vector.
template <typename Lower, typename Rhs>
void solve_lower_in_place(const Lower& l, Rhs& b) {
  for (Eigen::Index column = 0; column < b.cols(); ++column)
    for (Eigen::Index i = 0; i < l.rows(); ++i) {
      double sum = b(i, column);
      for (Eigen::Index k = 0; k < i; ++k) sum -= l(i, k) * b(k, column);
      b(i, column) = sum / l(i, i);
    }
}

/// L⁻ᵀ B (back substitution), column by column; B may be a vector.
template <typename Lower, typename Rhs>
void solve_lower_transposed_in_place(const Lower& l, Rhs& b) {
  for (Eigen::Index column = 0; column < b.cols(); ++column)
    for (Eigen::Index i = l.rows() - 1; i >= 0; --i) {
      double sum = b(i, column);
      for (Eigen::Index k = i + 1; k < l.rows(); ++k) sum -= l(k, i) * b(k, column);
      b(i, column) = sum / l(i, i);
    }
}

/// x = A⁻¹ b for A symmetric positive definite (lower triangle read). False, with `x`
/// unspecified, when A is not.
template <typename Matrix, typename Vector>
bool cholesky_solve(const Matrix& a, const Vector& b, Vector& x) {
  Matrix l;
  if (!cholesky_factor(a, l)) return false;
  x = b;
  solve_lower_in_place(l, x);
  solve_lower_transposed_in_place(l, x);
  return true;
}

/// A⁻¹ b for a symmetric A (lower triangle read): by Cholesky when A is positive definite (the
/// damped normal equations of a Levenberg–Marquardt step, nearly always), else by Eigen's LDLᵀ,
/// whose step may be non-finite: the callers then damp more.
template <typename Matrix, typename Vector>
Vector solve_symmetric(const Matrix& a, const Vector& b) {
  Vector x;
  if (cholesky_solve(a, b, x)) return x;
  return a.ldlt().solve(b);
}

}  // namespace primseg::detail
