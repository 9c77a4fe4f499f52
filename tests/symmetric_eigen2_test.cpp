// The closed-form 2x2 eigenvalue problems. The larger eigenvalue of a symmetric matrix, on
// matrices built from known spectra: rotations of diagonal matrices with close, equal, widely
// apart and negative eigenvalues, at scales from 1e-150 to 1e150. The smaller eigenpair of a
// generalised problem, on integer matrices whose eigenvalues are known to full precision however
// far apart (Fibonacci numbers: F(n+1) F(n-1) − F(n)² = 1), and on random ones by its residual.
#include "symmetric_eigen2.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>

namespace primseg::detail {
namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

TEST(SymmetricEigen2, LargerEigenvalueOfRotatedSpectraToRoundOffOfTheNorm) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(0, 2 * std::numbers::pi), unit(-1, 1);
  std::uniform_int_distribution<int> exponent(-150, 150), gap_exponent(-16, 0);
  for (int i = 0; i < 20000; ++i) {
    const double scale = std::pow(10.0, exponent(rng));
    const double larger = unit(rng);
    // Close pairs (gaps down to 1e-16 of the scale) as often as arbitrary ones.
    const double gap = i % 2 == 0 ? std::abs(unit(rng)) * std::pow(10.0, gap_exponent(rng))
                                  : std::abs(unit(rng)) * 2;
    const double smaller = larger - gap;
    const double turn = angle(rng);
    Eigen::Matrix2d rotation;
    rotation << std::cos(turn), -std::sin(turn), std::sin(turn), std::cos(turn);
    const Eigen::Matrix2d a = rotation *
                              Eigen::Vector2d(scale * smaller, scale * larger).asDiagonal() *
                              rotation.transpose();
    // The matrix built carries round-off of its own: a few ulps of its norm.
    const double norm = scale * std::max(std::abs(larger), std::abs(smaller));
    EXPECT_NEAR(larger_eigenvalue(a), scale * larger, 8 * kEpsilon * norm) << "case " << i;
  }
}

TEST(SymmetricEigen2, DiagonalAndScalarMatricesGiveTheirLargerEntryExactly) {
  EXPECT_EQ(larger_eigenvalue(Eigen::Vector2d(3.0, -5.0).asDiagonal()), 3.0);
  EXPECT_EQ(larger_eigenvalue(Eigen::Vector2d(-7.0, 0.25).asDiagonal()), 0.25);
  EXPECT_EQ(larger_eigenvalue(2.5 * Eigen::Matrix2d::Identity()), 2.5);
  EXPECT_EQ(larger_eigenvalue(Eigen::Matrix2d::Zero()), 0.0);
}

TEST(SymmetricEigen2, ReadsTheLowerTriangleAsEigensSolversDo) {
  Eigen::Matrix2d a;
  a << 1, 1e300, 0, 1;  // the upper entry is not read
  EXPECT_EQ(larger_eigenvalue(a), 1.0);
  a << 2, std::numeric_limits<double>::quiet_NaN(), 1, 2;
  EXPECT_DOUBLE_EQ(larger_eigenvalue(a), 3.0);
}

TEST(SymmetricEigen2, NonFiniteEntriesGiveANonFiniteEigenvalue) {
  for (const auto& [i, j] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}})
    for (const double bad :
         {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
      Eigen::Matrix2d a = Eigen::Matrix2d::Identity();
      a(i, j) = bad;
      EXPECT_FALSE(std::isfinite(larger_eigenvalue(a))) << i << j << bad;
    }
}

TEST(SymmetricEigen2, DifferenceOfProductsIsExactWhereTheNaiveFormulaCancelsToZero) {
  // (1 + 2⁻²⁷)(1 − 2⁻²⁷) = 1 − 2⁻⁵⁴ rounds to 1.
  const double up = 1 + std::ldexp(1.0, -27), down = 1 - std::ldexp(1.0, -27);
  ASSERT_EQ(up * down - 1.0 * 1.0, 0.0);
  EXPECT_EQ(difference_of_products(up, 1, 1, down), -std::ldexp(1.0, -54));
}

TEST(SymmetricEigen2, DifferenceOfProductsOfLargeIntegersToAnUlpOfTheExactDifference) {
  // Integers of 30 bits and d ≈ b c / a: products of 60 bits, exact in 64-bit integers and not
  // in doubles, whose difference (below a / 2) is.
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::int64_t> entry(std::int64_t{1} << 29,
                                                    (std::int64_t{1} << 30) - 1);
  int naive_misses = 0;
  for (int i = 0; i < 20000; ++i) {
    const std::int64_t a = entry(rng), b = entry(rng), c = entry(rng);
    const std::int64_t d = (b * c + a / 2) / a;
    const double exact = static_cast<double>(a * d - b * c);
    const double da = static_cast<double>(a), db = static_cast<double>(b),
                 dc = static_cast<double>(c), dd = static_cast<double>(d);
    EXPECT_LE(std::abs(difference_of_products(da, db, dc, dd) - exact), kEpsilon * std::abs(exact))
        << a << " " << b << " " << c << " " << d;
    naive_misses += da * dd - db * dc != exact;
  }
  EXPECT_GT(naive_misses, 10000);  // the cases do cancel
}

// F(n + 1), F(n), F(n − 1) for n = 42: F(43) F(41) − F(42)² = (−1)⁴² = 1.
constexpr std::int64_t kF43 = 433494437, kF42 = 267914296, kF41 = 165580141;

Eigen::Matrix2d matrix(std::int64_t d0, std::int64_t off, std::int64_t d1) {
  Eigen::Matrix2d m;
  m << static_cast<double>(d0), static_cast<double>(off), static_cast<double>(off),
      static_cast<double>(d1);
  return m;
}

TEST(SymmetricEigen2, SmallerGeneralizedEigenvalueToUlpsOfItselfEvenAtRatiosOf1e17) {
  // det A = det B = 1, so λ₁ λ₂ = 1 and λ₁ + λ₂ = t = a₀₀b₁₁ + a₁₁b₀₀ − 2a₁₀b₁₀: the smaller
  // eigenvalue is 2 / (t + √(t² − 4)), about 1 / t ≈ 1e-9 against a larger one of 1e9.
  const Eigen::Matrix2d a = matrix(kF43, kF42, kF41);
  for (const std::array<std::int64_t, 3>& b_entries :
       {std::array<std::int64_t, 3>{1, 0, 1}, {2, 1, 1}, {5, 2, 1}, {1, -3, 10}}) {
    const auto [b00, b10, b11] = b_entries;
    ASSERT_EQ(b00 * b11 - b10 * b10, 1);
    const Eigen::Matrix2d b = matrix(b00, b10, b11);
    const double t = static_cast<double>(kF43 * b11 + kF41 * b00 - 2 * kF42 * b10);
    const double smaller = 2 / (t + std::sqrt(t * t - 4));
    const SmallerGeneralizedEigenpair pair = smaller_generalized_eigenpair(a, b);
    ASSERT_TRUE(pair.valid);
    EXPECT_NEAR(pair.value, smaller, 4 * kEpsilon * smaller) << b;
    // The eigenvector: orthogonal to A − λ B's first row, whose entries λ barely changes.
    const double slope = -(a(0, 0) - smaller * b(0, 0)) / (a(1, 0) - smaller * b(1, 0));
    EXPECT_NEAR(pair.vector(1) / pair.vector(0), slope, 8 * kEpsilon * std::abs(slope)) << b;
    EXPECT_NEAR(pair.vector.dot(b * pair.vector), 1.0, 8 * kEpsilon) << b;
    // Eigen's iterative solver, on the same problem, works to round-off of the norm (1e9): the
    // smaller eigenvalue would come out as noise of 1e-7.
  }
}

TEST(SymmetricEigen2, SmallerGeneralizedEigenpairOfRandomProblemsIsBackwardStable) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> exponent(-100, 100);
  for (int i = 0; i < 20000; ++i) {
    const double scale_a = std::pow(10.0, exponent(rng)), scale_b = std::pow(10.0, exponent(rng));
    Eigen::Matrix2d a, factor;
    a << unit(rng), 0, unit(rng), unit(rng);
    a(0, 1) = a(1, 0);
    a *= scale_a;
    factor << unit(rng), 0, unit(rng), unit(rng);
    factor(0, 0) = 0.01 + std::abs(factor(0, 0));
    factor(1, 1) = 0.01 + std::abs(factor(1, 1));
    const Eigen::Matrix2d b = scale_b * factor * factor.transpose();
    const SmallerGeneralizedEigenpair pair = smaller_generalized_eigenpair(a, b);
    ASSERT_TRUE(pair.valid) << "case " << i;
    const Eigen::Vector2d& x = pair.vector;
    // ‖(A − λB) x‖ at round-off of ‖A‖ + |λ| ‖B‖, for x with xᵀ B x = 1.
    const double size = (a.norm() + std::abs(pair.value) * b.norm()) * x.norm();
    EXPECT_LE((a * x - pair.value * (b * x)).norm(), 32 * kEpsilon * size) << "case " << i;
    // (The form cancels where B is ill-conditioned: round-off of ‖B‖ ‖x‖², not of 1.)
    EXPECT_NEAR(x.dot(b * x), 1.0, 16 * kEpsilon * b.norm() * x.squaredNorm()) << "case " << i;
    // The smaller: no Rayleigh quotient lies below it, but for round-off.
    for (const Eigen::Vector2d& v :
         {Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1), Eigen::Vector2d(unit(rng), unit(rng))}) {
      const double quotient = v.dot(a * v) / v.dot(b * v);
      const double round_off = 64 * kEpsilon * (a.norm() + std::abs(pair.value) * b.norm()) *
                               v.squaredNorm() / v.dot(b * v);
      EXPECT_GE(quotient - pair.value, -round_off) << "case " << i;
    }
  }
}

TEST(SymmetricEigen2, SmallerGeneralizedEigenpairOfEqualEigenvaluesAndOfZero) {
  const Eigen::Matrix2d b = matrix(2, 1, 1);
  const SmallerGeneralizedEigenpair same = smaller_generalized_eigenpair(3 * b, b);
  ASSERT_TRUE(same.valid);
  EXPECT_DOUBLE_EQ(same.value, 3.0);
  EXPECT_NEAR(same.vector.dot(b * same.vector), 1.0, 4 * kEpsilon);
  const SmallerGeneralizedEigenpair zero =
      smaller_generalized_eigenpair(Eigen::Matrix2d::Zero(), b);
  ASSERT_TRUE(zero.valid);
  EXPECT_EQ(zero.value, 0.0);
}

TEST(SymmetricEigen2, SmallerGeneralizedEigenpairNeedsAPositiveDefiniteBAndFiniteEntries) {
  const Eigen::Matrix2d a = matrix(2, 1, 3);
  EXPECT_FALSE(smaller_generalized_eigenpair(a, matrix(1, 1, 1)).valid);   // singular
  EXPECT_FALSE(smaller_generalized_eigenpair(a, matrix(1, 2, 1)).valid);   // indefinite
  EXPECT_FALSE(smaller_generalized_eigenpair(a, matrix(-1, 0, 1)).valid);  // b₀₀ < 0
  EXPECT_FALSE(smaller_generalized_eigenpair(a, matrix(0, 0, 1)).valid);
  for (const auto& [i, j] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}})
    for (const double bad :
         {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
      Eigen::Matrix2d bad_a = a, bad_b = Eigen::Matrix2d::Identity();
      bad_a(i, j) = bad;
      bad_b(i, j) = bad;
      EXPECT_FALSE(smaller_generalized_eigenpair(bad_a, Eigen::Matrix2d::Identity()).valid);
      EXPECT_FALSE(smaller_generalized_eigenpair(a, bad_b).valid);
    }
  // The upper entries are not read.
  Eigen::Matrix2d upper_nan_a = a, upper_nan_b = Eigen::Matrix2d::Identity();
  upper_nan_a(0, 1) = upper_nan_b(0, 1) = std::numeric_limits<double>::quiet_NaN();
  const SmallerGeneralizedEigenpair pair = smaller_generalized_eigenpair(upper_nan_a, upper_nan_b);
  ASSERT_TRUE(pair.valid);
  EXPECT_DOUBLE_EQ(pair.value, 2.5 - std::sqrt(1.25));
}

}  // namespace
}  // namespace primseg::detail
