#pragma once
// Eigenvalues of symmetric 2x2 problems in closed form: the larger eigenvalue of a matrix, and the
// smaller eigenpair of a generalised problem A x = λ B x.
//
// Eigen's SelfAdjointEigenSolver gives eigenvalues to round-off of the norm, but instantiating it
// for a 2x2 matrix (tridiagonalisation, implicit QR and the dynamic-size code they reach) took a
// third of regularity/directions.cpp's compile time (g++ -O3: 44 s with it, 26 s without; session
// 58) and a quarter of primitives/cone.cpp's (medians of 5 runs: 47 s with it, 36 s without;
// session 59).

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

/// a·d − b·c to about an ulp of the result, however much the two products cancel (Kahan's
/// algorithm: the rounding error of b·c, recovered exactly by a fused multiply-add, is added back).
/// The determinant of a nearly singular 2x2 matrix keeps its relative accuracy this way.
inline double difference_of_products(double a, double b, double c, double d) {
  const double bc = b * c;
  const double bc_error = std::fma(-b, c, bc);  // bc − b·c, exactly
  return std::fma(a, d, -bc) + bc_error;
}

/// The smaller eigenvalue of A x = λ B x (A and B symmetric, B positive definite) and its
/// eigenvector.
struct SmallerGeneralizedEigenpair {
  bool valid = false;      ///< false when B is not positive definite or an entry is not finite
  double value = 0;        ///< the smaller eigenvalue
  Eigen::Vector2d vector;  ///< its eigenvector, xᵀ B x = 1, either sign
};

/// The smaller eigenpair of A x = λ B x, both matrices read from their lower triangles. The
/// eigenvalue of larger magnitude comes from the mean ± hypotenuse formula on L⁻¹ A L⁻ᵀ (B = L Lᵀ),
/// to a few ulps; the other one is the product of the two, det A / det B with both determinants
/// accurate (difference_of_products), over it. Each eigenvalue is thus accurate to a few ulps of
/// itself, not of the larger: Eigen's iterative solver, like any method that works on the norm,
/// gives a smaller eigenvalue ε‖A‖/|λ| off relatively, which is what a nearly exact fit's Taubin
/// ratio is. The eigenvector is orthogonal to the longer row of A − λ B. The determinants are
/// products of entries: they must neither overflow nor underflow (entries between 1e-150 and
/// 1e150 in magnitude, or zero).
inline SmallerGeneralizedEigenpair smaller_generalized_eigenpair(const Eigen::Matrix2d& a,
                                                                 const Eigen::Matrix2d& b) {
  SmallerGeneralizedEigenpair result;
  const double det_b = difference_of_products(b(0, 0), b(1, 0), b(1, 0), b(1, 1));
  if (!(b(0, 0) > 0) || !(det_b > 0) || !std::isfinite(det_b) || !std::isfinite(a(0, 0)) ||
      !std::isfinite(a(1, 0)) || !std::isfinite(a(1, 1)))
    return result;
  // C = L⁻¹ A L⁻ᵀ with L = [[l₀₀, 0], [l₁₀, l₁₁]], l₁₁² = det B / b₀₀.
  const double l00 = std::sqrt(b(0, 0)), l10 = b(1, 0) / l00, l11 = std::sqrt(det_b / b(0, 0));
  const double c00 = a(0, 0) / b(0, 0);
  const double c10 = (a(1, 0) - l10 * (a(0, 0) / l00)) / (l00 * l11);
  const double c11 =
      (a(1, 1) - 2 * l10 * (a(1, 0) / l00) + l10 * l10 * (a(0, 0) / b(0, 0))) / (l11 * l11);
  const double mean = 0.5 * (c00 + c11);
  const double hypotenuse = std::hypot(0.5 * (c00 - c11), c10);
  if (mean >= 0) {
    const double larger = mean + hypotenuse;
    // det A / larger / det B in this order: det A / det B alone overflows for ‖A‖ / ‖B‖ ≳ 1e154.
    const double det_a = difference_of_products(a(0, 0), a(1, 0), a(1, 0), a(1, 1));
    result.value = larger > 0 ? det_a / larger / det_b : 0;  // larger = 0: A = 0
  } else {
    result.value = mean - hypotenuse;
  }
  // x ⟂ the longer row of A − λ B, (r₀₀, r₁₀) or (r₁₀, r₁₁): x = (r₁₀, −r₀₀) or (r₁₁, −r₁₀).
  const double r00 = a(0, 0) - result.value * b(0, 0), r10 = a(1, 0) - result.value * b(1, 0),
               r11 = a(1, 1) - result.value * b(1, 1);
  Eigen::Vector2d x(r10, -r00);
  if (std::abs(r11) > std::abs(r00)) x = {r11, -r10};
  if (!(x.squaredNorm() > 0)) x = {1, 0};  // A = λ B: any vector
  const double norm_b =
      std::sqrt(x(0) * x(0) * b(0, 0) + 2 * x(0) * x(1) * b(1, 0) + x(1) * x(1) * b(1, 1));
  if (!(norm_b > 0) || !std::isfinite(norm_b)) return result;
  result.vector = x / norm_b;
  result.valid = std::isfinite(result.value);
  return result;
}

}  // namespace primseg::detail
