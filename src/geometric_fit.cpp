#include "primseg/geometric_fit.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "eigen_conversions.hpp"
#include "geometric_models.hpp"
#include "orthonormal_pair.hpp"
#include "primseg/error.hpp"
#include "primseg/primitives/primitive_fitter.hpp"
#include "primseg/primitives/torus.hpp"
#include "small_cholesky.hpp"

namespace primseg {
namespace detail {
namespace {

// Parameters: the normal tilted by (α, β) along its two orthogonal directions, the plane
// shifted by δ along the normal.
class PlaneModel final : public GeometricModel {
 public:
  PlaneModel(const Eigen::Vector3d& point, const Eigen::Vector3d& normal)
      : point_(point), normal_(normal.normalized()) {
    std::tie(u_, v_) = orthonormal_pair(normal_);
  }
  int parameter_count() const override { return 3; }
  double residual(const Eigen::Vector3d& x, double* gradient) const override {
    const Eigen::Vector3d y = x - point_;
    gradient[0] = u_.dot(y);
    gradient[1] = v_.dot(y);
    gradient[2] = -1;
    return normal_.dot(y);
  }
  std::unique_ptr<GeometricModel> stepped(const double* step) const override {
    return std::make_unique<PlaneModel>(point_ + step[2] * normal_,
                                        normal_ + step[0] * u_ + step[1] * v_);
  }
  Primitive primitive() const override {
    Primitive p;
    p.type = PrimitiveType::Plane;
    p.point = to_vec3(point_);
    p.axis = to_vec3(normal_);
    return p;
  }

 private:
  Eigen::Vector3d point_, normal_, u_, v_;
};

// Parameters: the centre's displacement and the radius change.
class SphereModel final : public GeometricModel {
 public:
  SphereModel(const Eigen::Vector3d& centre, double radius) : centre_(centre), radius_(radius) {}
  int parameter_count() const override { return 4; }
  double residual(const Eigen::Vector3d& x, double* gradient) const override {
    const Eigen::Vector3d y = x - centre_;
    const double length = y.norm();
    const Eigen::Vector3d direction =
        length > 0 ? Eigen::Vector3d(y / length) : Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) gradient[i] = -direction[i];
    gradient[3] = -1;
    return length - radius_;
  }
  std::unique_ptr<GeometricModel> stepped(const double* step) const override {
    return std::make_unique<SphereModel>(centre_ + Eigen::Vector3d(step[0], step[1], step[2]),
                                         radius_ + step[3]);
  }
  Primitive primitive() const override {
    Primitive p;
    p.type = PrimitiveType::Sphere;
    p.point = to_vec3(centre_);
    p.radius = radius_;
    return p;
  }

 private:
  Eigen::Vector3d centre_;
  double radius_;
};

// Parameters: the axis point moved by (s, t) across the axis, the axis tilted by (α, β), the
// radius change. Moving the point along the axis changes nothing, so it is not a parameter.
class CylinderModel final : public GeometricModel {
 public:
  CylinderModel(const Eigen::Vector3d& point, const Eigen::Vector3d& axis, double radius)
      : point_(point), axis_(axis.normalized()), radius_(radius) {
    std::tie(u_, v_) = orthonormal_pair(axis_);
  }
  int parameter_count() const override { return 5; }
  double residual(const Eigen::Vector3d& x, double* gradient) const override {
    const Eigen::Vector3d y = x - point_;
    const double along = axis_.dot(y);
    const Eigen::Vector3d radial = y - along * axis_;
    const double length = radial.norm();
    const Eigen::Vector3d direction =
        length > 0 ? Eigen::Vector3d(radial / length) : Eigen::Vector3d::Zero();
    const double du = direction.dot(u_), dv = direction.dot(v_);
    gradient[0] = -du;
    gradient[1] = -dv;
    gradient[2] = -du * along;
    gradient[3] = -dv * along;
    gradient[4] = -1;
    return length - radius_;
  }
  std::unique_ptr<GeometricModel> stepped(const double* step) const override {
    return std::make_unique<CylinderModel>(point_ + step[0] * u_ + step[1] * v_,
                                           axis_ + step[2] * u_ + step[3] * v_, radius_ + step[4]);
  }
  Primitive primitive() const override {
    Primitive p;
    p.type = PrimitiveType::Cylinder;
    p.point = to_vec3(point_);
    p.axis = to_vec3(axis_);
    p.radius = radius_;
    return p;
  }

 private:
  Eigen::Vector3d point_, axis_, u_, v_;
  double radius_;
};

// Parameters: the apex's displacement, the axis tilted by (α, β), the half-angle change. In the
// half-plane through the axis and x, with h along the axis and ρ across it, the signed distance
// to the generator is d = ρ cos θ − h sin θ (positive outside); t = h cos θ + ρ sin θ is the
// distance along the generator.
class ConeModel final : public GeometricModel {
 public:
  ConeModel(const Eigen::Vector3d& apex, const Eigen::Vector3d& axis, double half_angle)
      : apex_(apex), axis_(axis.normalized()), half_angle_(half_angle) {
    std::tie(u_, v_) = orthonormal_pair(axis_);
  }
  int parameter_count() const override { return 6; }
  double residual(const Eigen::Vector3d& x, double* gradient) const override {
    const Eigen::Vector3d y = x - apex_;
    const double h = axis_.dot(y);
    const Eigen::Vector3d radial = y - h * axis_;
    const double rho = radial.norm();
    const Eigen::Vector3d direction = rho > 0 ? Eigen::Vector3d(radial / rho) : u_;
    const double c = std::cos(half_angle_), s = std::sin(half_angle_);
    const double t = h * c + rho * s;
    // ∂d/∂apex = −(outward normal); tilting the axis by α along u moves h by ρ (r̂·u) and ρ by
    // −h (r̂·u), so ∂d/∂α = −t (r̂·u); ∂d/∂θ = −t.
    const Eigen::Vector3d normal = c * direction - s * axis_;
    for (int i = 0; i < 3; ++i) gradient[i] = -normal[i];
    gradient[3] = -t * direction.dot(u_);
    gradient[4] = -t * direction.dot(v_);
    gradient[5] = -t;
    return rho * c - h * s;
  }
  std::unique_ptr<GeometricModel> stepped(const double* step) const override {
    return std::make_unique<ConeModel>(apex_ + Eigen::Vector3d(step[0], step[1], step[2]),
                                       axis_ + step[3] * u_ + step[4] * v_, half_angle_ + step[5]);
  }
  Primitive primitive() const override {
    Primitive p;
    p.type = PrimitiveType::Cone;
    p.point = to_vec3(apex_);
    p.axis = to_vec3(axis_);
    p.half_angle = half_angle_;
    return p;
  }

 private:
  Eigen::Vector3d apex_, axis_, u_, v_;
  double half_angle_;
};

// Parameters: the centre's displacement, the axis tilted by (α, β), the major and minor radius
// changes. In the half-plane through the axis and x (h along the axis, ρ across it) the tube's
// centre is at (ρ, h) = (R, 0) and d = |(ρ − R, h)| − r.
class TorusModel final : public GeometricModel {
 public:
  TorusModel(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis, double major_radius,
             double minor_radius)
      : centre_(centre),
        axis_(axis.normalized()),
        major_radius_(major_radius),
        minor_radius_(minor_radius) {
    std::tie(u_, v_) = orthonormal_pair(axis_);
  }
  int parameter_count() const override { return 7; }
  double residual(const Eigen::Vector3d& x, double* gradient) const override {
    const Eigen::Vector3d y = x - centre_;
    const double h = axis_.dot(y);
    const Eigen::Vector3d radial = y - h * axis_;
    const double rho = radial.norm();
    const Eigen::Vector3d direction = rho > 0 ? Eigen::Vector3d(radial / rho) : u_;
    // Not std::hypot (a tenth of a torus-enabled hierarchy's time): the points are normalised to
    // the unit ball, so the squares cannot overflow for any torus whose fit is finite.
    const double across = rho - major_radius_;
    const double tube = std::sqrt(across * across + h * h);
    // Unit direction from the tube's centre to x, in the (ρ, h) half-plane.
    const double q_rho = tube > 0 ? across / tube : 1;
    const double q_h = tube > 0 ? h / tube : 0;
    const Eigen::Vector3d normal = q_rho * direction + q_h * axis_;
    for (int i = 0; i < 3; ++i) gradient[i] = -normal[i];
    // Tilting the axis by α along u moves h by ρ (r̂·u) and ρ by −h (r̂·u).
    const double tilt = q_h * rho - q_rho * h;
    gradient[3] = tilt * direction.dot(u_);
    gradient[4] = tilt * direction.dot(v_);
    gradient[5] = -q_rho;
    gradient[6] = -1;
    return tube - minor_radius_;
  }
  std::unique_ptr<GeometricModel> stepped(const double* step) const override {
    return std::make_unique<TorusModel>(centre_ + Eigen::Vector3d(step[0], step[1], step[2]),
                                        axis_ + step[3] * u_ + step[4] * v_,
                                        major_radius_ + step[5], minor_radius_ + step[6]);
  }
  Primitive primitive() const override {
    Primitive p;
    p.type = PrimitiveType::Torus;
    p.point = to_vec3(centre_);
    p.axis = to_vec3(axis_);
    p.radius = major_radius_;
    p.minor_radius = minor_radius_;
    return p;
  }

 private:
  Eigen::Vector3d centre_, axis_, u_, v_;
  double major_radius_, minor_radius_;
};

}  // namespace

std::unique_ptr<GeometricModel> geometric_model_for(const Primitive& p) {
  switch (p.type) {
    case PrimitiveType::Plane:
      return std::make_unique<PlaneModel>(to_eigen(p.point), to_eigen(p.axis));
    case PrimitiveType::Sphere:
      return std::make_unique<SphereModel>(to_eigen(p.point), p.radius);
    case PrimitiveType::Cylinder:
      return std::make_unique<CylinderModel>(to_eigen(p.point), to_eigen(p.axis), p.radius);
    case PrimitiveType::Cone:
      return std::make_unique<ConeModel>(to_eigen(p.point), to_eigen(p.axis), p.half_angle);
    case PrimitiveType::Torus:
      return std::make_unique<TorusModel>(to_eigen(p.point), to_eigen(p.axis), p.radius,
                                          p.minor_radius);
  }
  return nullptr;
}

}  // namespace detail

namespace {

using detail::GeometricModel;
using detail::to_eigen;
using detail::to_vec3;

struct Normalised {
  std::vector<Eigen::Vector3d> points;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  int exponent = 0;      // one normalised unit is 2^exponent input units
  bool widened = false;  // the scale is the starting primitive's, not the points'
};

// A primitive's offset from the points or its radii may be at most this many normalised units:
// distances up to it square without overflow.
constexpr int kMaxPrimitiveExponent = 256;

// Points centred on their weighted centroid and scaled by a power of two to within the unit
// ball: conditioning of the normal equations, and no overflow of squared distances. If the
// starting primitive lies much farther than the points' own size (a tree file may pair a cluster
// of subnormal coordinates with a plane at distance 2), the scale is set by it instead, at
// 2^kMaxPrimitiveExponent units, where its distances stay finite.
Normalised normalise(std::span<const Vec3> points, std::span<const double> weights,
                     const Primitive& initial) {
  Normalised n;
  double total = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    sum += weights[i] * Eigen::Vector3d(points[i][0], points[i][1], points[i][2]);
    total += weights[i];
  }
  if (total > 0) n.centre = sum / total;
  double extent = 0;
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) extent = std::max(extent, std::abs(p[k] - n.centre[k]));
  if (extent > 0) std::frexp(extent, &n.exponent);
  double reach = std::max(std::abs(initial.radius), std::abs(initial.minor_radius));
  for (int k = 0; k < 3; ++k) reach = std::max(reach, std::abs(initial.point[k] - n.centre[k]));
  int reach_exponent = 0;
  std::frexp(reach, &reach_exponent);
  if (std::isfinite(reach) && reach_exponent - n.exponent > kMaxPrimitiveExponent) {
    n.exponent = reach_exponent - kMaxPrimitiveExponent;
    n.widened = true;
  }
  // Multiplying by a power of two rounds as ldexp does (both round the exact product once), at a
  // fraction of its cost; ldexp only where 2^−exponent itself overflows (subnormal extents).
  const double scale = std::ldexp(1.0, -n.exponent);
  n.points.reserve(points.size());
  for (const Vec3& p : points) {
    const Eigen::Vector3d offset(p[0] - n.centre.x(), p[1] - n.centre.y(), p[2] - n.centre.z());
    if (std::isfinite(scale))
      n.points.emplace_back(offset * scale);
    else
      n.points.emplace_back(std::ldexp(offset.x(), -n.exponent),
                            std::ldexp(offset.y(), -n.exponent),
                            std::ldexp(offset.z(), -n.exponent));
  }
  return n;
}

Primitive to_normalised(Primitive p, const Normalised& n) {
  for (int k = 0; k < 3; ++k) p.point[k] = std::ldexp(p.point[k] - n.centre[k], -n.exponent);
  p.radius = std::ldexp(p.radius, -n.exponent);
  p.minor_radius = std::ldexp(p.minor_radius, -n.exponent);
  return p;
}

Primitive from_normalised(Primitive p, const Normalised& n) {
  for (int k = 0; k < 3; ++k) p.point[k] = std::ldexp(p.point[k], n.exponent) + n.centre[k];
  p.radius = std::ldexp(p.radius, n.exponent);
  p.minor_radius = std::ldexp(p.minor_radius, n.exponent);
  return p;
}

// At most kMaxParameters: fixed-capacity matrices, no heap and no blocked products (the torus fit
// runs Levenberg–Marquardt on its 32-point sample for every candidate merge).
using NormalMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0,
                                   detail::kMaxParameters, detail::kMaxParameters>;
using ParameterVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, detail::kMaxParameters, 1>;

// Σ w d² of a model, and the Gauss–Newton normal equations at it (N = Σ w g gᵀ, rhs = −Σ w d g,
// g = ∂d/∂parameters) from the same pass over the points: a step the fit accepts has its next
// system ready.
struct LinearisedCost {
  double cost = 0;
  NormalMatrix normal;
  ParameterVector rhs;

  LinearisedCost(const GeometricModel& model, const Normalised& n,
                 std::span<const double> weights) {
    const int count = model.parameter_count();
    if (count < 1 || count > detail::kMaxParameters)
      throw std::logic_error("a geometric model has 1 to kMaxParameters parameters");
    // accumulate<count>: one instance per possible count.
    [&]<int... K>(std::integer_sequence<int, K...>) {
      ((count == K + 1 ? accumulate<K + 1>(model, n, weights) : void()), ...);
    }
    (std::make_integer_sequence<int, detail::kMaxParameters>());
  }

 private:
  // The parameter count as a constant: the per-point update of the upper triangle unrolls (a
  // dynamic-size outer product cost most of a fit).
  template <int K>
  void accumulate(const GeometricModel& model, const Normalised& n,
                  std::span<const double> weights) {
    static_assert(K <= detail::kMaxParameters);
    double upper[K][K] = {}, minus_rhs[K] = {};
    double gradient[detail::kMaxParameters];
    for (std::size_t i = 0; i < n.points.size(); ++i) {
      const double d = model.residual(n.points[i], gradient);
      const double w = weights[i], wd = w * d;
      cost += wd * d;
      for (int a = 0; a < K; ++a) {
        const double wg = w * gradient[a];
        for (int b = a; b < K; ++b) upper[a][b] += wg * gradient[b];
        minus_rhs[a] += wd * gradient[a];
      }
    }
    normal.resize(K, K);
    rhs.resize(K);
    for (int a = 0; a < K; ++a) {
      for (int b = a; b < K; ++b) normal(a, b) = normal(b, a) = upper[a][b];
      rhs(a) = -minus_rhs[a];
    }
  }
};

// The canonical form of primitive.hpp, in the normalised frame (weighted centroid at 0).
Primitive canonical(Primitive p, const Primitive& initial_normalised) {
  const Eigen::Vector3d axis = to_eigen(p.axis);
  const Eigen::Vector3d point = to_eigen(p.point);
  if (p.type == PrimitiveType::Plane) {
    const Eigen::Vector3d initial = to_eigen(initial_normalised.axis);
    const Eigen::Vector3d normal = axis.dot(initial) < 0 ? Eigen::Vector3d(-axis) : axis;
    // The centroid (the origin here) projected on the plane.
    const Eigen::Vector3d foot = normal * normal.dot(point);
    p.axis = to_vec3(normal);
    p.point = to_vec3(foot);
  } else if (p.type == PrimitiveType::Cylinder) {
    const Eigen::Vector3d a = canonical_axis(axis);
    const Eigen::Vector3d foot = point - a * a.dot(point);
    p.axis = to_vec3(a);
    p.point = to_vec3(foot);
    p.radius = std::abs(p.radius);
  } else if (p.type == PrimitiveType::Sphere) {
    p.radius = std::abs(p.radius);
  } else if (p.type == PrimitiveType::Cone) {
    p.axis = to_vec3(axis);  // from the apex into the cone: keep its side
  } else if (p.type == PrimitiveType::Torus) {
    p.axis = to_vec3(canonical_axis(axis));
  }
  return p;
}

}  // namespace

bool has_geometric_model(PrimitiveType type) {
  Primitive p;
  p.type = type;
  p.axis = {0, 0, 1};
  return detail::geometric_model_for(p) != nullptr;
}

namespace {

// fit_geometric() in one frame; `widened` tells whether the frame was scaled to the start.
GeometricFit fit_in_one_frame(const Primitive& initial, std::span<const Vec3> points,
                              std::span<const double> weights, const GeometricFitOptions& options,
                              bool& widened) {
  const Normalised n = normalise(points, weights, initial);
  widened = n.widened;
  const Primitive start = to_normalised(initial, n);
  std::unique_ptr<GeometricModel> model = detail::geometric_model_for(start);
  GeometricFit result;
  result.primitive = initial;
  if (model) {
    const int k = model->parameter_count();
    LinearisedCost current(*model, n, weights);
    double lambda = 1e-3;
    while (result.iterations < options.max_iterations && current.cost > 0) {
      bool accepted = false;
      while (lambda < 1e16) {
        NormalMatrix damped = current.normal;
        for (int j = 0; j < k; ++j) damped(j, j) += lambda * current.normal(j, j) + 1e-300;
        // N is positive semi-definite; the damping makes it definite unless a parameter has no
        // effect at all.
        const ParameterVector step = detail::solve_symmetric(damped, current.rhs);
        if (!step.allFinite()) {
          lambda *= 10;
          continue;
        }
        // The linearised residuals' Σ w d² falls by 2 sᵀ rhs − sᵀ N s along the step s, and more
        // damping only shortens the step: once that is within the tolerance the fit has
        // converged, and trying ever more damped steps (a full pass over the points each) would
        // at best find a decrease of round-off size.
        const double predicted = 2 * step.dot(current.rhs) - step.dot(current.normal * step);
        if (!(predicted > options.relative_tolerance * current.cost)) break;
        std::unique_ptr<GeometricModel> candidate = model->stepped(step.data());
        LinearisedCost trial(*candidate, n, weights);
        if (trial.cost < current.cost) {
          const bool converged =
              current.cost - trial.cost <= options.relative_tolerance * current.cost;
          model = std::move(candidate);
          current = std::move(trial);
          lambda = std::max(lambda / 10, 1e-12);
          accepted = !converged;
          ++result.iterations;
          break;
        }
        lambda *= 10;
      }
      if (!accepted) break;
    }
    if (result.iterations > 0)
      result.primitive = from_normalised(canonical(model->primitive(), start), n);
  }
  // Distances of the final primitive, in the normalised frame then scaled back.
  const Primitive final_normalised = to_normalised(result.primitive, n);
  double sum = 0, total = 0, largest = 0;
  for (std::size_t i = 0; i < n.points.size(); ++i) {
    const Eigen::Vector3d& x = n.points[i];
    const double d = final_normalised.distance(to_vec3(x));
    sum += weights[i] * d * d;
    total += weights[i];
    if (weights[i] > 0) largest = std::max(largest, d);
  }
  result.rms = total > 0 ? std::ldexp(std::sqrt(sum / total), n.exponent) : 0.0;
  result.max = std::ldexp(largest, n.exponent);
  return result;
}

}  // namespace

GeometricFit fit_geometric(const Primitive& initial, std::span<const Vec3> points,
                           std::span<const double> weights, const GeometricFitOptions& options) {
  if (points.size() != weights.size())
    throw InvalidInputError("fit_geometric: " + std::to_string(points.size()) + " points but " +
                            std::to_string(weights.size()) + " weights");
  for (double w : weights)
    if (!(w >= 0) || !std::isfinite(w))
      throw InvalidInputError("fit_geometric: weights must be finite and non-negative");
  bool widened = false;
  GeometricFit fit = fit_in_one_frame(initial, points, weights, options, widened);
  if (!widened || fit.iterations == 0 || fit.iterations >= options.max_iterations) return fit;
  // A frame scaled to a faraway start resolves the points only to its own round-off: once the fit
  // has come to them, it goes on in their frame.
  GeometricFitOptions rest = options;
  rest.max_iterations -= fit.iterations;
  GeometricFit closer = fit_in_one_frame(fit.primitive, points, weights, rest, widened);
  closer.iterations += fit.iterations;
  return closer.rms <= fit.rms ? closer : fit;
}

GeometricFit fit_geometric_or_sphere(const Primitive& initial, std::span<const Vec3> points,
                                     std::span<const double> weights,
                                     const GeometricFitOptions& options) {
  const GeometricFit fit = fit_geometric(initial, points, weights, options);
  if (fit.iterations == 0 || fit.primitive.type != PrimitiveType::Torus ||
      !torus_ring_vanishes(fit.primitive))
    return fit;
  Primitive sphere;
  sphere.type = PrimitiveType::Sphere;
  sphere.point = fit.primitive.point;
  sphere.radius = fit.primitive.minor_radius;
  GeometricFit refitted = fit_geometric(sphere, points, weights, options);  // that sphere at worst
  refitted.iterations += fit.iterations;
  return refitted;
}

}  // namespace primseg
