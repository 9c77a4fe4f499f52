#pragma once
// Pratt's constrained algebraic fit of a circle (D = 2) or sphere (D = 3) from centred moments.
//
// Minimises Σ w (A|p|² + B·p + C)² subject to |B|² − 4AC = 1. For a sphere with centre c and
// radius r the numerator is A²(|p−c|² − r²)² and the constraint 4A²r², so the minimum is exactly
// min over spheres of Σ w (|p−c|² − r²)² / (4r²): a first-order equivalent of Σ w (|p−c| − r)²,
// with planes (A = 0) as the limit, so flat data yields a huge radius instead of noise.

#include <Eigen/Core>
#include <limits>

namespace primseg::detail {

template <int D>
struct CentredMomentsND {
  double weight = 0;                   // Σ w
  Eigen::Matrix<double, D, D> second;  // Σ w p pᵀ
  Eigen::Matrix<double, D, 1> third;   // Σ w p |p|²
  double fourth = 0;                   // Σ w |p|⁴
};

/// The eigen-decomposition of CentredMomentsND::second: ascending eigenvalues, unit eigenvectors
/// as columns.
template <int D>
struct MomentEigensystem {
  Eigen::Matrix<double, D, 1> values;
  Eigen::Matrix<double, D, D> vectors;
};

template <int D>
struct PrattResult {
  bool valid = false;
  /// True when the fit stopped because its objective is at least the objective to beat (then
  /// nothing else is set but objective_minimum).
  bool beaten = false;
  double error = 0;                    // the minimum objective (≥ 0)
  Eigen::Matrix<double, D, 1> centre;  // relative to the centroid
  double radius = 0;
  /// The minimum of Pratt's objective over all circles/spheres and their plane limit (a lower
  /// bound of it by at most round-off), also when the fit is not valid; 0 for flat or empty data.
  /// When beaten: the objective to beat, a lower bound of that minimum.
  double objective_minimum = 0;
};

/// Largest radius, relative to the RMS spread of the points about their centroid, still taken
/// as curved: beyond it the sagitta is under 1/2000 of the spread, which is a plane.
inline constexpr double kMaxRelativeRadius = 1e3;

/// Pratt's fit. With a finite `objective_to_beat`, a fit whose minimum objective is certainly at
/// least that (one evaluation of the secular function) returns at once, beaten; the others are
/// the same, bit for bit, as without it.
template <int D>
PrattResult<D> pratt_fit(const CentredMomentsND<D>& moments,
                         double objective_to_beat = std::numeric_limits<double>::infinity());
/// The same with the eigen-decomposition of moments.second already known.
template <int D>
PrattResult<D> pratt_fit(const CentredMomentsND<D>& moments, const MomentEigensystem<D>& second,
                         double objective_to_beat = std::numeric_limits<double>::infinity());

extern template PrattResult<2> pratt_fit<2>(const CentredMomentsND<2>&, double);
extern template PrattResult<3> pratt_fit<3>(const CentredMomentsND<3>&, double);
extern template PrattResult<2> pratt_fit<2>(const CentredMomentsND<2>&,
                                            const MomentEigensystem<2>&, double);
extern template PrattResult<3> pratt_fit<3>(const CentredMomentsND<3>&,
                                            const MomentEigensystem<3>&, double);

}  // namespace primseg::detail
