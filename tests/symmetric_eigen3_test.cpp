// The closed-form 3x3 symmetric eigen-solver against Eigen's iterative one, on the matrices the
// fits meet: nearly flat and nearly collinear point sets (tiny smallest eigenvalues), close and
// equal pairs, indefinite tensors, and the degenerate inputs.
#include "symmetric_eigen3.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <random>

namespace primseg::detail {
namespace {

struct Case {
  Eigen::Matrix3d matrix;
  const char* kind;
};

// Random rotations of diagonal matrices whose spectra have the shapes the fits see, at scales
// from 1e-8 to 1e8.
std::vector<Case> hard_cases() {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> gauss(0, 1);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::vector<Case> cases;
  for (int i = 0; i < 6000; ++i) {
    Eigen::Quaterniond q(gauss(rng), gauss(rng), gauss(rng), gauss(rng));
    q.normalize();
    const Eigen::Matrix3d rotation = q.toRotationMatrix();
    const double tiny = std::pow(10.0, -16 * std::abs(uniform(rng)));
    const double close = std::pow(10.0, -12 * std::abs(uniform(rng)));
    Eigen::Vector3d spectrum;
    const char* kind = "";
    switch (i % 6) {
      case 0:
        spectrum << tiny, 1, 1 + close;
        kind = "flat disc";
        break;
      case 1:
        spectrum << tiny, tiny * (1 + close), 1;
        kind = "collinear";
        break;
      case 2:
        spectrum << tiny, 0.3, 1;
        kind = "flat";
        break;
      case 3:
        spectrum << uniform(rng), uniform(rng), uniform(rng);
        kind = "indefinite";
        break;
      case 4:
        spectrum << -1, -1 - close, tiny;
        kind = "concave cylinder tensor";
        break;
      default:
        spectrum << 1, 1, 1 + close;
        kind = "nearly scalar";
    }
    Eigen::Matrix3d m = rotation * spectrum.asDiagonal() * rotation.transpose();
    m = 0.5 * (m + m.transpose()).eval();
    cases.push_back({m * std::pow(10.0, 8 * uniform(rng)), kind});
  }
  return cases;
}

TEST(SymmetricEigen3, AgreesWithTheIterativeSolverToRoundOffOfTheNorm) {
  for (const Case& c : hard_cases()) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> reference(c.matrix);
    const SymmetricEigen3 e = symmetric_eigen3(c.matrix);
    const double norm = c.matrix.cwiseAbs().maxCoeff();
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(e.values(k), reference.eigenvalues()(k), 1e-14 * norm) << c.kind;
      // Each column is an eigenvector of its eigenvalue, and they are orthonormal.
      const Eigen::Vector3d v = e.vectors.col(k);
      EXPECT_LE((c.matrix * v - e.values(k) * v).norm(), 1e-14 * norm) << c.kind;
    }
    EXPECT_LE((e.vectors.transpose() * e.vectors - Eigen::Matrix3d::Identity()).norm(), 1e-14)
        << c.kind;
    EXPECT_LE(e.values(0), e.values(1));
    EXPECT_LE(e.values(1), e.values(2));
  }
}

TEST(SymmetricEigen3, SmallestAndDominantPairsAreThoseOfTheFullDecomposition) {
  for (const Case& c : hard_cases()) {
    const SymmetricEigen3 all = symmetric_eigen3(c.matrix);
    const double norm = c.matrix.cwiseAbs().maxCoeff();
    const Eigenpair smallest = smallest_eigenpair(c.matrix);
    EXPECT_NEAR(smallest.value, all.values(0), 1e-14 * norm) << c.kind;
    EXPECT_LE((c.matrix * smallest.vector - smallest.value * smallest.vector).norm(), 1e-14 * norm)
        << c.kind;
    EXPECT_NEAR(smallest.vector.norm(), 1, 1e-14);
    const Eigenpair dominant = dominant_eigenpair(c.matrix);
    EXPECT_NEAR(std::abs(dominant.value),
                std::max(std::abs(all.values(0)), std::abs(all.values(2))), 1e-14 * norm)
        << c.kind;
    EXPECT_LE((c.matrix * dominant.vector - dominant.value * dominant.vector).norm(), 1e-14 * norm)
        << c.kind;
  }
}

// The sphere's fit asks for the whole decomposition after the plane's smallest pair: going on
// from the pair's vectors must give what the whole decomposition alone gives, bit for bit, or
// the trees would change.
TEST(SymmetricEigen3, GoingOnFromTheSmallestPairGivesTheSameBits) {
  std::vector<Case> cases = hard_cases();
  for (const Eigen::Matrix3d& m :
       {Eigen::Matrix3d(Eigen::Matrix3d::Zero()),
        Eigen::Matrix3d(2.5 * Eigen::Matrix3d::Identity()),
        Eigen::Matrix3d(Eigen::Vector3d(1, 2, 2) * Eigen::Vector3d(1, 2, 2).transpose())})
    cases.push_back({m, "degenerate"});
  int counts[3] = {0, 0, 0};
  for (const Case& c : cases) {
    Eigenpair smallest;
    Eigen::Vector3d isolated, orthogonal;
    const int count = smallest_eigenpair(c.matrix, &smallest, &isolated, &orthogonal);
    ASSERT_GE(count, 0);
    ASSERT_LE(count, 2);
    ++counts[count];
    const Eigenpair alone = smallest_eigenpair(c.matrix);
    EXPECT_EQ(smallest.value, alone.value) << c.kind;
    EXPECT_EQ(smallest.vector, alone.vector) << c.kind;
    if (count == 0) continue;
    const SymmetricEigen3 from = symmetric_eigen3_from(c.matrix, count, isolated, orthogonal);
    const SymmetricEigen3 whole = symmetric_eigen3(c.matrix);
    EXPECT_EQ(from.values, whole.values) << c.kind;
    EXPECT_EQ(from.vectors, whole.vectors) << c.kind;
  }
  // Each path is taken: degenerate matrices, and the isolated eigenvalue the smallest or not.
  EXPECT_GT(counts[0], 0);
  EXPECT_GT(counts[1], 1000);
  EXPECT_GT(counts[2], 1000);
}

TEST(SymmetricEigen3, SmallEigenvaluesOfScatterMatricesHaveTheIterativeSolversAccuracy) {
  // A scatter matrix of points near a plane: its smallest eigenvalue is the plane's whole error,
  // and must not carry more round-off than the iterative solver's (a few ulps of the norm).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss(0, 1);
  for (double thickness : {1e-2, 1e-4, 1e-6}) {
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d p(gauss(rng), 0.5 * gauss(rng), thickness * gauss(rng));
      scatter += p * p.transpose();
    }
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    scatter = rotation * scatter * rotation.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> reference(scatter);
    const double lambda = reference.eigenvalues()(0);
    EXPECT_NEAR(smallest_eigenpair(scatter).value, lambda, 4e-16 * scatter.norm() + 1e-9 * lambda)
        << thickness;
  }
}

TEST(SymmetricEigen3, DegenerateInputs) {
  const SymmetricEigen3 zero = symmetric_eigen3(Eigen::Matrix3d::Zero());
  EXPECT_EQ(zero.values, Eigen::Vector3d::Zero());
  EXPECT_EQ(zero.vectors, Eigen::Matrix3d::Identity());
  const SymmetricEigen3 scalar = symmetric_eigen3(2.5 * Eigen::Matrix3d::Identity());
  EXPECT_EQ(scalar.values, Eigen::Vector3d::Constant(2.5));
  Eigen::Matrix3d rank_one = Eigen::Vector3d(1, 2, 2) * Eigen::Vector3d(1, 2, 2).transpose();
  const SymmetricEigen3 one = symmetric_eigen3(rank_one);
  EXPECT_NEAR(one.values(2), 9, 1e-14 * 9);
  EXPECT_NEAR(one.values(0), 0, 1e-14 * 9);
  EXPECT_NEAR(one.values(1), 0, 1e-14 * 9);
  Eigen::Matrix3d not_finite = Eigen::Matrix3d::Identity();
  not_finite(1, 2) = not_finite(2, 1) = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(symmetric_eigen3(not_finite).values.array().isNaN().all());
  not_finite(1, 2) = not_finite(2, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(symmetric_eigen3(not_finite).values.array().isNaN().all());
}

}  // namespace
}  // namespace primseg::detail
