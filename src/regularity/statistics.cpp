// The tests and tolerances the stages of regularize() share: χ² bounds, Bonferroni
// corrections, tolerated scores, residual excesses.
#include "regularity/stages.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <numeric>
#include <vector>

#include "orthonormal_pair.hpp"

namespace primseg::detail {

bool within_tolerance(double size, double tolerance) {
  return tolerance > 0 && size <= tolerance;
}

double tolerated(double score, double bound, double size, double tolerance) {
  if (!(tolerance > 0)) return score;
  const double scaled = size / tolerance;
  return std::min(score, bound * scaled * scaled);
}

namespace {

// The s ≥ low with P(|N(0, 1)| > s) = erfc(s / √2) = tail, by bisection over [low, low + 40].
double two_sided_quantile(double tail, double low) {
  double high = low + 40;
  for (int step = 0; step < 100; ++step) {
    const double middle = (low + high) / 2;
    (std::erfc(middle / std::numbers::sqrt2) > tail ? low : high) = middle;
  }
  return high;
}

}  // namespace

double chi_square_bound(double significance, std::size_t freedom) {
  if (freedom == 1) return significance * significance;
  const double tail = std::erfc(significance / std::numbers::sqrt2);
  if (freedom == 2) return -2 * std::log(tail);
  // Wilson–Hilferty: (χ²ₖ / k)^(1/3) is nearly normal, of mean 1 − 2/(9k) and variance 2/(9k).
  // Its quantile is at the one-sided normal quantile z of the tail, P(N > z) = tail: the
  // significance itself would be the quantile of half the tail (a χ² bound 12% too high at k = 3).
  const double z = two_sided_quantile(2 * tail, 0);
  const double k = static_cast<double>(freedom), spread = 2 / (9 * k);
  return k * std::pow(1 - spread + z * std::sqrt(spread), 3);
}

double residual_excess(double own_rms, double joint_rms, std::size_t count, double bound,
                       int parameters, double length_tolerance) {
  const double n = static_cast<double>(count);
  const double rise = n * (joint_rms * joint_rms - own_rms * own_rms);
  return tolerated(rise / (bound * own_rms * own_rms * n / (n - parameters)), 1,
                   std::sqrt(std::max(rise / n, 0.0)), length_tolerance);
}

double residual_pull(double own_rms, double joint_rms, std::size_t count) {
  const double n = static_cast<double>(count);
  return n * n * (joint_rms * joint_rms - own_rms * own_rms);
}

std::vector<std::size_t> every_member(std::size_t count) {
  std::vector<std::size_t> members(count);
  std::iota(members.begin(), members.end(), 0);
  return members;
}

Eigen::Matrix2d tilt_in_frame(const Eigen::Vector3d& direction, const Eigen::Matrix3d& covariance) {
  const auto [u, v] = orthonormal_pair(direction);
  Eigen::Matrix<double, 3, 2> frame;
  frame << u, v;
  return frame.transpose() * covariance * frame;
}

double family_significance(double significance, std::size_t tests) {
  return two_sided_quantile(
      std::erfc(significance / std::numbers::sqrt2) / static_cast<double>(tests), significance);
}

double guard_bound(double significance, std::size_t tests, std::size_t lost) {
  return chi_square_bound(family_significance(significance, tests), lost);
}

}  // namespace primseg::detail
