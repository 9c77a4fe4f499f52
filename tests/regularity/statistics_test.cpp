// The tests regularize()'s stages share (src/regularity/statistics.cpp), against their
// definitions: χ² quantiles against the exact tail, Bonferroni corrections against the normal
// tail, tolerated scores and residual excesses at their bounds; and which member a guard sends
// back (member_that_leaves()).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <numeric>
#include <utility>
#include <vector>

#include "orthonormal_pair.hpp"
#include "regularity/stages.hpp"

namespace primseg {
namespace {

using detail::chi_square_bound;
using detail::family_significance;
using detail::GuardExcess;
using detail::kLeavingSetSize;
using detail::kLeavingTrials;
using detail::member_that_leaves;
using detail::residual_excess;
using detail::tolerated;
using detail::within_tolerance;

// P(|N(0, 1)| > s).
double two_sided_tail(double s) {
  return std::erfc(s / std::numbers::sqrt2);
}

// P(χ²ₖ > x), exact for integer k: Q(k/2, x/2) by its finite sums (even k from e^(−x/2), odd k
// from the normal tail of √x).
double chi_square_tail(std::size_t k, double x) {
  const double half = x / 2;
  double term = 0, sum = 0;
  if (k % 2 == 0) {
    term = std::exp(-half);
    for (std::size_t i = 0; i < k / 2; ++i) {
      sum += term;
      term *= half / static_cast<double>(i + 1);
    }
    return sum;
  }
  sum = two_sided_tail(std::sqrt(x));
  // Q(a + 1, y) = Q(a, y) + yᵃ e⁻ʸ / Γ(a + 1), from Q(1/2, y) = erfc(√y).
  term = std::sqrt(4 * half / std::numbers::pi) * std::exp(-half);
  for (std::size_t i = 1; i < (k + 1) / 2; ++i) {
    sum += term;
    term *= half / (static_cast<double>(i) + 0.5);
  }
  return sum;
}

// The exact x with P(χ²ₖ > x) = tail, by bisection.
double chi_square_quantile(std::size_t k, double tail) {
  double low = 0, high = 1000;
  for (int step = 0; step < 200; ++step) {
    const double middle = (low + high) / 2;
    (chi_square_tail(k, middle) > tail ? low : high) = middle;
  }
  return (low + high) / 2;
}

TEST(RegularityStatistics, TheExactChiSquareTailIsRight) {
  // The test's own reference, on values known in closed form: χ²₁ is a squared normal, and the
  // mean of χ²ₖ is k (∫ P(χ² > x) dx).
  EXPECT_NEAR(chi_square_tail(1, 9), two_sided_tail(3), 1e-15);
  for (const std::size_t k : {2, 3, 4, 7}) {
    double mean = 0;
    for (double x = 0.0005; x < 200; x += 0.001) mean += chi_square_tail(k, x) * 0.001;
    EXPECT_NEAR(mean, static_cast<double>(k), 1e-6) << k;
  }
}

TEST(RegularityStatistics, ChiSquareBoundIsExactForOneAndTwoDegreesOfFreedom) {
  for (const double s : {1.0, 2.0, 3.0, 4.5}) {
    EXPECT_DOUBLE_EQ(chi_square_bound(s, 1), s * s);
    EXPECT_NEAR(chi_square_tail(2, chi_square_bound(s, 2)) / two_sided_tail(s), 1, 1e-12) << s;
  }
}

TEST(RegularityStatistics, ChiSquareBoundIsNearTheExactQuantileFromThreeDegreesOfFreedom) {
  // Wilson–Hilferty, as documented: within 1.1% of the exact quantile at a significance of 3
  // (the largest error at k = 3), 0.5% at 2. Taking the significance itself as the normal
  // quantile, as the bound once did, was 12% off at k = 3.
  for (const auto& [significance, error] : {std::pair{3.0, 0.011}, std::pair{2.0, 0.005}})
    for (std::size_t k = 3; k <= 300; ++k) {
      const double exact = chi_square_quantile(k, two_sided_tail(significance));
      EXPECT_NEAR(chi_square_bound(significance, k) / exact, 1, error) << significance << ", " << k;
    }
}

TEST(RegularityStatistics, FamilySignificanceSharesTheTailAmongTheTests) {
  for (const double s : {2.0, 3.0}) {
    EXPECT_NEAR(family_significance(s, 1), s, 1e-12);
    double previous = s;
    for (const std::size_t tests : {2, 10, 100, 10000}) {
      const double each = family_significance(s, tests);
      EXPECT_NEAR(two_sided_tail(each) * static_cast<double>(tests) / two_sided_tail(s), 1, 1e-10)
          << s << ", " << tests;
      EXPECT_GT(each, previous);
      previous = each;
    }
  }
}

TEST(RegularityStatistics, ATolerancePassesWhatItCoversAndRanksItBySize) {
  EXPECT_FALSE(within_tolerance(0, 0));
  EXPECT_TRUE(within_tolerance(1e-4, 2e-4));
  EXPECT_FALSE(within_tolerance(3e-4, 2e-4));
  // No tolerance: the score as it is.
  EXPECT_EQ(tolerated(42, 9, 1e-4, 0), 42);
  // Within the tolerance a difference passes (its score at most the bound), ranked by its size.
  const double near = tolerated(1e6, 9, 0.5e-4, 2e-4), far = tolerated(1e6, 9, 1.5e-4, 2e-4);
  EXPECT_LE(far, 9);
  EXPECT_LT(near, far);
  EXPECT_DOUBLE_EQ(tolerated(1e6, 9, 2e-4, 2e-4), 9);
  // A score already lower stays.
  EXPECT_EQ(tolerated(1, 9, 1.5e-4, 2e-4), 1);
}

TEST(RegularityStatistics, ResidualExcessIsOneAtTheBound) {
  // n points whose own fit (p parameters) left rms r: their variance is n r² / (n − p), and a
  // joint fit whose residual sum rises by significance² times it is exactly at the bound.
  const double r = 0.01, significance2 = 9;
  const std::size_t n = 50;
  const int p = 3;
  const double variance = static_cast<double>(n) * r * r / (static_cast<double>(n) - p);
  const double joint = std::sqrt(r * r + significance2 * variance / static_cast<double>(n));
  EXPECT_NEAR(residual_excess(r, joint, n, significance2, p, 0), 1, 1e-12);
  EXPECT_LT(residual_excess(r, r, n, significance2, p, 0), 1e-12);
  // With a length tolerance, the rise of the mean square against its square when lower: half
  // the tolerance's square is a quarter.
  const double rise = std::sqrt(joint * joint - r * r);
  EXPECT_NEAR(residual_excess(r, joint, n, significance2, p, 2 * rise), 0.25, 1e-12);
  EXPECT_NEAR(residual_excess(r, joint, n, significance2, p, rise), 1, 1e-12);
}

TEST(RegularityStatistics, TiltInFrameIsTheCovarianceInTheAxisFrame) {
  const Eigen::Vector3d direction = Eigen::Vector3d(1, 2, 3).normalized();
  const auto [u, v] = detail::orthonormal_pair(direction);
  // A tilt of variance 4 along u and 9 along v (and none along the direction itself).
  const Eigen::Matrix3d covariance = 4 * u * u.transpose() + 9 * v * v.transpose();
  const Eigen::Matrix2d in_frame = detail::tilt_in_frame(direction, covariance);
  EXPECT_NEAR(in_frame(0, 0), 4, 1e-12);
  EXPECT_NEAR(in_frame(1, 1), 9, 1e-12);
  EXPECT_NEAR(in_frame(0, 1), 0, 1e-12);
  EXPECT_NEAR(in_frame(1, 0), 0, 1e-12);
}

// A guard of n members, member `worst` of the largest excess: what each member's absence leaves
// (`left[j]`), each member's pull, and which members member_that_leaves() refitted without.
struct Guard {
  std::vector<GuardExcess> left;
  std::vector<double> pull;
  std::vector<std::size_t> refitted;

  // What the refit without a member holds: which member it left out, and how it explains the
  // others.
  struct Refitted {
    std::size_t member;
    GuardExcess excess;
  };

  std::pair<std::size_t, std::size_t> leave(std::size_t worst) {
    refitted.clear();
    const auto [leaving, without] = member_that_leaves(
        detail::every_member(left.size()), worst, [&](std::size_t j) { return pull[j]; },
        [&](std::size_t j) {
          refitted.push_back(j);
          return Refitted{j, left[j]};
        });
    return {leaving, without.member};
  }
};

TEST(RegularityGuard, TheWorstLeavesWhenItsAbsenceLeavesNoneFailing) {
  Guard guard{{{1, 50}, {1, 40}, {0, 1}, {1, 30}}, {9, 8, 1, 7}, {}};
  EXPECT_EQ(guard.leave(2), (std::pair<std::size_t, std::size_t>{2, 2}));
  EXPECT_EQ(guard.refitted, std::vector<std::size_t>{2});  // nothing else refitted
}

TEST(RegularityGuard, AMemberThatPullsHarderLeavesWhenItsAbsenceLeavesFewerFailing) {
  // The worst (3, pull 2) leaves two others failing; without member 1, which pulls hardest, none
  // fails; member 0, pulling harder too, leaves one.
  Guard guard{{{1, 5}, {0, 1}, {2, 3}, {2, 90}}, {4, 6, 1, 2}, {}};
  EXPECT_EQ(guard.leave(3).first, 1u);
  // The worst first, then those pulling harder, in the members' order.
  EXPECT_EQ(guard.refitted, (std::vector<std::size_t>{3, 0, 1}));
  // Of members leaving as many failing, the smallest largest excess.
  guard.left = {{1, 5}, {1, 4}, {2, 3}, {2, 90}};
  EXPECT_EQ(guard.leave(3).first, 1u);
}

TEST(RegularityGuard, TheWorstStaysTheChoiceUnlessAnotherLeavesFewerFailing) {
  // Member 0's absence lowers the largest excess but fixes no one: the worst leaves.
  Guard guard{{{2, 3}, {2, 9}, {2, 80}}, {5, 1, 2}, {}};
  EXPECT_EQ(guard.leave(2).first, 2u);
  // Members pulling less than the worst are not refitted without.
  EXPECT_EQ(guard.refitted, (std::vector<std::size_t>{2, 0}));
}

TEST(RegularityGuard, AtMostTheTrialsThatPullHardestAndNoneInLargeSets) {
  const std::size_t n = kLeavingSetSize;
  Guard guard{std::vector<GuardExcess>(n, {3, 10}), std::vector<double>(n), {}};
  for (std::size_t j = 0; j < n; ++j) guard.pull[j] = static_cast<double>(j);
  guard.leave(0);
  // The worst, then the kLeavingTrials pulling hardest, in the members' order.
  std::vector<std::size_t> expected{0};
  for (std::size_t j = n - kLeavingTrials; j < n; ++j) expected.push_back(j);
  EXPECT_EQ(guard.refitted, expected);
  guard.left.push_back({3, 10});
  guard.pull.push_back(100);
  EXPECT_EQ(guard.leave(0).first, 0u);
  EXPECT_EQ(guard.refitted, std::vector<std::size_t>{0});
}

}  // namespace
}  // namespace primseg
