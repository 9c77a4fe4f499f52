// Pratt's fit from moments against a direct computation on the points themselves.
#include "primitives/pratt_fit.hpp"

#include <gtest/gtest.h>

#include <random>

namespace primseg::detail {
namespace {

template <int D>
struct WeightedPoints {
  std::vector<Eigen::Matrix<double, D, 1>> points;
  std::vector<double> weights;

  // Σ w (|p − c|² − r²)² / (4r²): the objective Pratt's fit minimises exactly.
  double objective(const Eigen::Matrix<double, D, 1>& c, double r) const {
    double sum = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double a = (points[i] - c).squaredNorm() - r * r;
      sum += weights[i] * a * a / (4 * r * r);
    }
    return sum;
  }
  CentredMomentsND<D> centred_moments(Eigen::Matrix<double, D, 1>* centroid) const {
    *centroid = Eigen::Matrix<double, D, 1>::Zero();
    double w = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      *centroid += weights[i] * points[i];
      w += weights[i];
    }
    *centroid /= w;
    CentredMomentsND<D> m;
    m.weight = w;
    m.second.setZero();
    m.third.setZero();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Matrix<double, D, 1> p = points[i] - *centroid;
      m.second += weights[i] * p * p.transpose();
      m.third += weights[i] * p * p.squaredNorm();
      m.fourth += weights[i] * p.squaredNorm() * p.squaredNorm();
    }
    return m;
  }
};

template <int D>
WeightedPoints<D> noisy_arc(std::mt19937_64& rng, double noise, double arc) {
  std::normal_distribution<double> gauss(0, 1);
  std::uniform_real_distribution<double> uniform(0, 1);
  WeightedPoints<D> set;
  Eigen::Matrix<double, D, 1> centre;
  for (int a = 0; a < D; ++a) centre(a) = 3 * gauss(rng);
  const double radius = 0.5 + 4 * uniform(rng);
  for (int i = 0; i < 60; ++i) {
    Eigen::Matrix<double, D, 1> direction;
    direction(0) = std::cos(arc * uniform(rng));
    direction(1) = std::sin(arc * uniform(rng));
    if constexpr (D == 3) direction(2) = 0.3 * gauss(rng);
    direction.normalize();
    set.points.push_back(centre + direction * radius * (1 + noise * gauss(rng)));
    set.weights.push_back(0.2 + uniform(rng));
  }
  return set;
}

template <int D>
void check_against_direct_objective(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0, 1);
  for (int trial = 0; trial < 30; ++trial) {
    const WeightedPoints<D> set = noisy_arc<D>(rng, 0.02, 1.5 + trial * 0.15);
    Eigen::Matrix<double, D, 1> centroid;
    const PrattResult<D> fit = pratt_fit<D>(set.centred_moments(&centroid));
    ASSERT_TRUE(fit.valid);
    const Eigen::Matrix<double, D, 1> c = centroid + fit.centre;
    const double direct = set.objective(c, fit.radius);
    // The reported error is the objective at the reported sphere...
    EXPECT_NEAR(fit.error, direct, 1e-9 * direct);
    // ... and no nearby sphere does better: it is the minimum.
    for (int probe = 0; probe < 50; ++probe) {
      Eigen::Matrix<double, D, 1> dc;
      for (int a = 0; a < D; ++a) dc(a) = gauss(rng);
      const double step = 1e-3 * fit.radius;
      EXPECT_GE(set.objective(c + step * dc, fit.radius * (1 + 1e-3 * gauss(rng))),
                direct * (1 - 1e-12));
    }
  }
}

TEST(PrattFit, SphereMinimisesTheNormalisedAlgebraicDistance) {
  check_against_direct_objective<3>(3);
}
TEST(PrattFit, CircleMinimisesTheNormalisedAlgebraicDistance) {
  check_against_direct_objective<2>(4);
}

// With an objective to beat: beaten exactly when the minimum objective is at least that, and
// otherwise the same fit, bit for bit, as without it.
template <int D>
void check_objective_to_beat(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  int beaten = 0, solved = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const WeightedPoints<D> set = noisy_arc<D>(rng, trial % 2 ? 0.02 : 0.2, 0.5 + trial * 0.1);
    Eigen::Matrix<double, D, 1> centroid;
    const CentredMomentsND<D> moments = set.centred_moments(&centroid);
    const PrattResult<D> full = pratt_fit<D>(moments);
    ASSERT_GT(full.objective_minimum, 0);
    for (double factor : {0.01, 0.5, 0.999, 1.001, 2.0, 100.0}) {
      const double beat = factor * full.objective_minimum;
      const PrattResult<D> fit = pratt_fit<D>(moments, beat);
      if (fit.beaten) {
        ++beaten;
        EXPECT_GE(full.objective_minimum, beat * (1 - 1e-9)) << factor;
        EXPECT_FALSE(fit.valid);
        EXPECT_EQ(fit.objective_minimum, beat);  // a lower bound of the minimum
      } else {
        ++solved;
        EXPECT_LT(full.objective_minimum, beat * (1 + 1e-9)) << factor;
        EXPECT_EQ(fit.valid, full.valid);
        EXPECT_EQ(fit.error, full.error);
        EXPECT_EQ(fit.radius, full.radius);
        EXPECT_EQ(fit.centre, full.centre);
        EXPECT_EQ(fit.objective_minimum, full.objective_minimum);
      }
    }
  }
  // Both outcomes occur (0.01 and 0.5 are beaten unless the plane limit is nearer; 2 and 100
  // never are).
  EXPECT_GT(beaten, 40);
  EXPECT_GT(solved, 80);
}

TEST(PrattFit, SphereStopsOnceBeatenAndIsUnchangedOtherwise) {
  check_objective_to_beat<3>(5);
}
TEST(PrattFit, CircleStopsOnceBeatenAndIsUnchangedOtherwise) {
  check_objective_to_beat<2>(6);
}

TEST(PrattFit, FlatDataIsNotACurve) {
  WeightedPoints<2> line;
  for (int i = 0; i < 20; ++i) {
    line.points.push_back(Eigen::Vector2d(i * 0.1, 0.5 * i * 0.1 + 1));
    line.weights.push_back(1);
  }
  Eigen::Vector2d centroid;
  EXPECT_FALSE(pratt_fit<2>(line.centred_moments(&centroid)).valid);
}

}  // namespace
}  // namespace primseg::detail
