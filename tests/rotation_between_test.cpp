// The shortest rotation between two directions: it takes the first onto the second, turns about
// an axis orthogonal to both (no twist), by the angle between them; opposite directions make a
// half turn.
#include "rotation_between.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace primseg::detail {
namespace {

constexpr double kRoundOff = 2.3e-16;  // an ulp of 1

// Round-off grows toward opposite directions, as 1 / (1 + cos θ): the axis is their cross
// product, whose length is sin θ, and the half-angle's cosine comes from 1 + cos θ.
void expect_shortest(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  const Eigen::Quaterniond q = rotation_between(from, to);
  const Eigen::Vector3d a = from.normalized(), b = to.normalized();
  const double condition = 1 / (1 + a.dot(b));
  EXPECT_NEAR(q.norm(), 1, 4 * kRoundOff * condition);
  EXPECT_LE((q * a - b).norm(), 12 * kRoundOff * condition)
      << from.transpose() << " -> " << to.transpose();
  // About an axis orthogonal to both, by the angle between them.
  EXPECT_NEAR(q.vec().dot(a), 0, 2 * kRoundOff * std::sqrt(condition));
  EXPECT_NEAR(q.vec().dot(b), 0, 2 * kRoundOff * std::sqrt(condition));
  const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
  EXPECT_NEAR(2 * std::atan2(q.vec().norm(), q.w()), angle, 4 * kRoundOff * condition);
}

TEST(RotationBetween, TakesTheFirstDirectionOntoTheSecondByTheShortestTurn) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> gauss(0, 1);
  std::uniform_real_distribution<double> length(0.01, 100);
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector3d from(gauss(rng), gauss(rng), gauss(rng));
    const Eigen::Vector3d to(gauss(rng), gauss(rng), gauss(rng));
    expect_shortest(length(rng) * from, length(rng) * to);
  }
}

TEST(RotationBetween, NearlyEqualAndNearlyOppositeDirections) {
  const Eigen::Vector3d a = Eigen::Vector3d(1, 2, 3).normalized();
  const Eigen::Vector3d tilt = Eigen::Vector3d(3, -1, 0).normalized();  // orthogonal to a
  for (const double epsilon : {0.0, 1e-12, 1e-8, 1e-4}) {
    expect_shortest(a, (a + epsilon * tilt).normalized());
    expect_shortest(a, (-a + epsilon * tilt).normalized());
  }
}

TEST(RotationBetween, OppositeDirectionsMakeAHalfTurnAboutAnOrthogonalAxis) {
  for (const Eigen::Vector3d& a :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(-2, 5, 1)}) {
    const Eigen::Quaterniond q = rotation_between(a, -3 * a);
    EXPECT_NEAR(q.w(), 0, kRoundOff);
    EXPECT_NEAR(q.vec().norm(), 1, 4 * kRoundOff);
    EXPECT_NEAR(q.vec().dot(a.normalized()), 0, 4 * kRoundOff);
    EXPECT_LE((q * a.normalized() + a.normalized()).norm(), 8 * kRoundOff);
  }
}

}  // namespace
}  // namespace primseg::detail
