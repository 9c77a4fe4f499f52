#pragma once
// The per-type models of the geometric fit: a signed distance to the current primitive, its
// gradient with respect to a small local parametrisation around it (zero = the current
// primitive), and the primitive a step of those parameters leads to. A new type (cone, torus)
// plugs in by adding one model and a case in geometric_model_for().

#include <Eigen/Core>
#include <memory>

#include "primseg/primitive.hpp"

namespace primseg::detail {

class GeometricModel {
 public:
  virtual ~GeometricModel() = default;
  /// Number of local parameters (at most kMaxParameters).
  virtual int parameter_count() const = 0;
  /// Signed distance from x to the current primitive; writes ∂d/∂parameter into `gradient`
  /// (parameter_count() entries).
  virtual double residual(const Eigen::Vector3d& x, double* gradient) const = 0;
  /// The primitive reached by moving the local parameters by `step` (parameter_count()
  /// entries): a new model around it.
  virtual std::unique_ptr<GeometricModel> stepped(const double* step) const = 0;
  /// The current primitive.
  virtual Primitive primitive() const = 0;
};

inline constexpr int kMaxParameters = 8;

/// The model of a primitive, or nullptr for a type without one.
std::unique_ptr<GeometricModel> geometric_model_for(const Primitive& primitive);

}  // namespace primseg::detail
