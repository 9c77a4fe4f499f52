// The closed-form larger eigenvalue of a symmetric 2x2 matrix, on matrices built from known
// spectra: rotations of diagonal matrices with close, equal, widely apart and negative eigenvalues,
// at scales from 1e-150 to 1e150.
#include "symmetric_eigen2.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

}  // namespace
}  // namespace primseg::detail
