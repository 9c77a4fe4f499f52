#include "support/reference_fits.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg::testing {
namespace {

template <int D>
struct Moments2 {
  double weight = 0;
  Eigen::Matrix<double, D, D> second;
  Eigen::Matrix<double, D, 1> third;
  double fourth = 0;
};

template <int D>
struct Pratt {
  bool valid = false;
  double error = 0;
  Eigen::Matrix<double, D, 1> centre;
  double radius = 0;
};

// The previous Pratt solver, unchanged but for its iteration cap.
template <int D>
Pratt<D> pratt(const Moments2<D>& moments) {
  using Vector = Eigen::Matrix<double, D, 1>;
  using Matrix = Eigen::Matrix<double, D, D>;
  Pratt<D> result;
  const double w = moments.weight;
  const double spread2 = moments.second.trace() / w;
  if (!(w > 0) || !(spread2 > 0) || !std::isfinite(spread2)) return result;
  const double scale = 1 / std::sqrt(spread2);
  const double scale2 = scale * scale;
  const double f = moments.fourth * scale2 * scale2;
  const Vector t = moments.third * (scale2 * scale);
  const Matrix c = moments.second * scale2;
  const double s = c.trace();
  Eigen::SelfAdjointEigenSolver<Matrix> eigen(c);
  const Vector lambda = eigen.eigenvalues();
  const Vector tau = eigen.eigenvectors().transpose() * t;
  auto g = [&](double eta, double* derivative) {
    double value = f - (s + 2 * eta) * (s + 2 * eta) / w;
    double slope = -4 * (s + 2 * eta) / w;
    for (int k = 0; k < D; ++k) {
      const double gap = lambda(k) - eta;
      value -= tau(k) * tau(k) / gap;
      slope -= tau(k) * tau(k) / (gap * gap);
    }
    *derivative = slope;
    return value;
  };
  double lo = 0, hi = lambda(0);
  if (!(hi > 0)) return result;
  double eta = 0, slope = 0;
  double value = g(eta, &slope);
  if (value > 0) {
    for (int iteration = 0; iteration < 400; ++iteration) {
      if (value > 0)
        lo = eta;
      else
        hi = eta;
      double next = eta - value / slope;
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (!(std::abs(next - eta) > 1e-15 * std::max(hi, 1e-300))) break;
      eta = next;
      value = g(eta, &slope);
      if (value == 0) break;
    }
  } else {
    eta = 0;
  }
  if (!(lambda(0) - eta > 1e-12 * lambda(D - 1))) return result;
  Vector b = Vector::Zero();
  for (int k = 0; k < D; ++k) b -= eigen.eigenvectors().col(k) * (tau(k) / (lambda(k) - eta));
  const double relative_radius = std::sqrt(b.squaredNorm() / 4 + (s + 2 * eta) / w);
  if (!(relative_radius <= 1e3)) return result;
  result.valid = true;
  result.error = std::max(0.0, eta) / scale2;
  result.centre = -b / 2 / scale;
  result.radius = relative_radius / scale;
  return result;
}

ReferenceFit plane(const ClusterStats& c) {
  ReferenceFit fit;
  fit.valid = true;
  if (c.moments.weight() > 0) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(c.moments.second_moment());
    fit.error = std::max(0.0, solver.eigenvalues()(0));
  }
  if (c.area > 0) fit.normal_alignment = c.normal_sum.norm() / c.area;
  return fit;
}

ReferenceFit cylinder(const ClusterStats& c) {
  ReferenceFit fit;
  if (c.triangle_count < 4 || !(c.area > 0)) return fit;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(c.edges.tensor_matrix());
  const Eigen::Vector3d lambda = solver.eigenvalues();
  const int largest = std::abs(lambda(0)) > std::abs(lambda(2)) ? 0 : 2;
  if (!(std::abs(lambda(largest)) > 1e-9 * std::sqrt(c.area))) return fit;
  const Eigen::Vector3d axis = canonical_axis(solver.eigenvectors().col(largest).normalized());
  Eigen::Index least_aligned;
  axis.cwiseAbs().minCoeff(&least_aligned);
  const Eigen::Vector3d u = axis.cross(Eigen::Vector3d::Unit(least_aligned)).normalized();
  const Eigen::Vector3d v = axis.cross(u);
  Eigen::Matrix<double, 2, 3> basis;
  basis.row(0) = u.transpose();
  basis.row(1) = v.transpose();
  const Eigen::Matrix3d projector = Eigen::Matrix3d::Identity() - axis * axis.transpose();
  Moments2<2> m;
  m.weight = c.moments.weight();
  m.second = basis * c.moments.second_moment() * basis.transpose();
  m.third = basis * c.moments.third_moment_contracted(projector);
  m.fourth = c.moments.fourth_moment_contracted(projector);
  const Pratt<2> circle = pratt(m);
  if (!circle.valid) return fit;
  const Eigen::Vector3d point = c.moments.origin() + basis.transpose() * circle.centre;
  fit.normal_alignment = c.normal_alignment(projector, point, circle.radius);
  if (fit.normal_alignment < kMinNormalAlignment) return fit;
  fit.valid = true;
  fit.error = circle.error;
  return fit;
}

ReferenceFit sphere(const ClusterStats& c) {
  ReferenceFit fit;
  if (c.triangle_count < 4) return fit;
  Moments2<3> m;
  m.weight = c.moments.weight();
  m.second = c.moments.second_moment();
  m.third = c.moments.third_moment_contracted(Eigen::Matrix3d::Identity());
  m.fourth = c.moments.fourth_moment_contracted(Eigen::Matrix3d::Identity());
  const Pratt<3> s = pratt(m);
  if (!s.valid) return fit;
  fit.normal_alignment =
      c.normal_alignment(Eigen::Matrix3d::Identity(), c.moments.origin() + s.centre, s.radius);
  if (fit.normal_alignment < kMinNormalAlignment) return fit;
  fit.valid = true;
  fit.error = s.error;
  return fit;
}

}  // namespace

ReferenceModel reference_model(const ClusterStats& centred, const HierarchyOptions& options) {
  const double zero_level = options.zero_cost_tolerance * centred.moments.second_moment().trace();
  ReferenceModel model;
  std::vector<PrimitiveType> types = options.primitives;
  std::sort(types.begin(), types.end());
  bool found = false;
  double best_alignment = 0;
  for (PrimitiveType type : types) {
    ReferenceFit fit = type == PrimitiveType::Plane      ? plane(centred)
                       : type == PrimitiveType::Cylinder ? cylinder(centred)
                                                         : sphere(centred);
    if (fit.valid) {
      if (fit.error <= zero_level) fit.error = 0;
      fit.cost = fit.error * options.type_penalty[static_cast<int>(type)];
      const bool better_exact =
          found && fit.cost == 0 && model.cost == 0 && fit.normal_alignment > best_alignment + 1e-6;
      if (!found || fit.cost < model.cost || better_exact) {
        model.type = type;
        model.cost = fit.cost;
        best_alignment = fit.normal_alignment;
        found = true;
      }
    }
    model.fits[static_cast<int>(type)] = fit;
    if (found && model.cost == 0 && best_alignment >= 1 - 1e-6) break;
  }
  if (!found) {
    ReferenceFit fit = plane(centred);
    if (fit.error <= zero_level) fit.error = 0;
    model.type = PrimitiveType::Plane;
    model.cost = fit.error * options.type_penalty[0];
  }
  return model;
}

}  // namespace primseg::testing
