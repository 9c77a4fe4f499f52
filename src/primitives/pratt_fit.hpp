#pragma once
// Pratt's constrained algebraic fit of a circle (D = 2) or sphere (D = 3) from centred moments.
//
// Minimises Σ w (A|p|² + B·p + C)² subject to |B|² − 4AC = 1. For a sphere with centre c and
// radius r the numerator is A²(|p−c|² − r²)² and the constraint 4A²r², so the minimum is exactly
// min over spheres of Σ w (|p−c|² − r²)² / (4r²): a first-order equivalent of Σ w (|p−c| − r)²,
// with planes (A = 0) as the limit, so flat data yields a huge radius instead of noise.

#include <Eigen/Core>
#include <limits>

namespace primseg {
class ClusterView;
}

namespace primseg::detail {

template <int D>
struct CentredMomentsND {
  double weight = 0;                   // Σ w
  Eigen::Matrix<double, D, D> second;  // Σ w p pᵀ
  Eigen::Matrix<double, D, 1> third;   // Σ w p |p|²
  double fourth = 0;                   // Σ w |p|⁴
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
/// least that returns at once, beaten (one evaluation of the secular function, without an
/// eigen-decomposition); the others are the same, bit for bit, as without it.
/// `smallest_eigenvalue`: that of moments.second if known (NaN: computed here).
template <int D>
PrattResult<D> pratt_fit(const CentredMomentsND<D>& moments,
                         double objective_to_beat = std::numeric_limits<double>::infinity(),
                         double smallest_eigenvalue = std::numeric_limits<double>::quiet_NaN());

/// The sphere of a cluster: pratt_fit() of its moments, with the smallest eigenvalue and the
/// eigen-decomposition of its second moment from the view, which computes them once for every fit
/// that reads them (the plane's smallest pair takes most of the steps of the whole decomposition).
PrattResult<3> pratt_fit(const ClusterView& cluster, double objective_to_beat);

extern template PrattResult<2> pratt_fit<2>(const CentredMomentsND<2>&, double, double);
extern template PrattResult<3> pratt_fit<3>(const CentredMomentsND<3>&, double, double);

}  // namespace primseg::detail
