#include "small_cholesky.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <cmath>
#include <limits>

#include "shape_generator/random.hpp"

namespace primseg::detail {
namespace {

// A symmetric positive definite matrix with condition number about `condition`: Q D Qᵀ with Q
// from the QR of a random matrix and D spread logarithmically.
template <typename Matrix>
Matrix random_positive_definite(Eigen::Index n, double condition, std::uint64_t seed) {
  shape_detail::SplitMix64 random(seed);
  Eigen::MatrixXd m(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) m(i, j) = random.normal();
  const Eigen::MatrixXd q = Eigen::HouseholderQR<Eigen::MatrixXd>(m).householderQ();
  Eigen::VectorXd d(n);
  for (Eigen::Index i = 0; i < n; ++i)
    d(i) = n == 1 ? 1.0 : std::pow(condition, -static_cast<double>(i) / static_cast<double>(n - 1));
  const Eigen::MatrixXd a = q * d.asDiagonal() * q.transpose();
  return Matrix(0.5 * (a + a.transpose()));
}

template <typename Matrix, typename Vector>
void expect_solves(const Matrix& a, std::uint64_t seed, double condition) {
  shape_detail::SplitMix64 random(seed);
  Vector b(a.rows());
  for (Eigen::Index i = 0; i < b.size(); ++i) b(i) = random.normal();
  Vector x;
  ASSERT_TRUE(cholesky_solve(a, b, x));
  const Vector reference = a.llt().solve(b);
  // Backward stable: the residual is round-off of A's and x's sizes; the error is that times
  // the condition number.
  const auto n = static_cast<double>(a.rows());
  EXPECT_LE((a * x - b).norm(), 1e-14 * n * a.norm() * x.norm());
  EXPECT_LE((x - reference).norm(), 1e-14 * n * condition * reference.norm());
}

TEST(SmallCholesky, SolvesFixedSizeSystemsLikeEigensLlt) {
  using Matrix6 = Eigen::Matrix<double, 6, 6>;
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  for (const double condition : {1.0, 1e3, 1e8})
    for (std::uint64_t seed = 1; seed <= 20; ++seed)
      expect_solves<Matrix6, Vector6>(random_positive_definite<Matrix6>(6, condition, seed),
                                      seed + 100, condition);
}

TEST(SmallCholesky, SolvesBoundedDynamicSizesOneToEight) {
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 8, 8>;
  using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 8, 1>;
  for (Eigen::Index n = 1; n <= 8; ++n)
    for (std::uint64_t seed = 1; seed <= 10; ++seed)
      expect_solves<Matrix, Vector>(random_positive_definite<Matrix>(n, 1e4, seed), seed + 7, 1e4);
}

TEST(SmallCholesky, FactorReproducesTheMatrix) {
  using Matrix = Eigen::Matrix<double, 5, 5>;
  const Matrix a = random_positive_definite<Matrix>(5, 1e2, 3);
  Matrix l;
  ASSERT_TRUE(cholesky_factor(a, l));
  EXPECT_TRUE(l.isLowerTriangular(0.0));
  EXPECT_LE((l * l.transpose() - a).norm(), 1e-14 * a.norm());
  // Triangular solves against Eigen's.
  const Matrix b = random_positive_definite<Matrix>(5, 10, 4);
  Matrix forward = b, backward = b;
  solve_lower_in_place(l, forward);
  solve_lower_transposed_in_place(l, backward);
  EXPECT_LE((l * forward - b).norm(), 1e-13 * b.norm());
  EXPECT_LE((l.transpose() * backward - b).norm(), 1e-13 * b.norm());
}

TEST(SmallCholesky, RefusesMatricesThatAreNotPositiveDefinite) {
  using Matrix3 = Eigen::Matrix3d;
  const Eigen::Vector3d b(1, 2, 3);
  Eigen::Vector3d x;
  Matrix3 indefinite = Matrix3::Identity();
  indefinite(2, 2) = -1;
  EXPECT_FALSE(cholesky_solve(indefinite, b, x));
  Matrix3 singular = Matrix3::Identity();
  singular(1, 1) = 0;
  EXPECT_FALSE(cholesky_solve(singular, b, x));
  // Positive semi-definite of rank 1: the second pivot is round-off, not positive.
  const Eigen::Vector3d v(1, 2, 3);
  EXPECT_FALSE(cholesky_solve(Matrix3(v * v.transpose()), b, x));
  Matrix3 with_nan = Matrix3::Identity();
  with_nan(1, 0) = with_nan(0, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(cholesky_solve(with_nan, b, x));
  Matrix3 with_infinity = Matrix3::Identity();
  with_infinity(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(cholesky_solve(with_infinity, b, x));
}

TEST(SmallCholesky, SolveSymmetricFallsBackToLdltWhenIndefinite) {
  Eigen::Matrix3d indefinite = Eigen::Matrix3d::Identity();
  indefinite(2, 2) = -2;
  indefinite(0, 1) = indefinite(1, 0) = 0.5;
  const Eigen::Vector3d b(1, 2, 3);
  const Eigen::Vector3d x = solve_symmetric(indefinite, b);
  EXPECT_LE((indefinite * x - b).norm(), 1e-14 * b.norm());
  const Eigen::Matrix3d definite = random_positive_definite<Eigen::Matrix3d>(3, 1e2, 5);
  EXPECT_LE((definite * solve_symmetric(definite, b) - b).norm(), 1e-13 * b.norm());
}

}  // namespace
}  // namespace primseg::detail
