// Plane: weighted PCA. The normal is the eigenvector of the smallest eigenvalue of the centred
// second moment matrix S, and the L2 error Σ w (n·(x − c))² is exactly that eigenvalue.
#include "primseg/primitives/plane.hpp"

namespace primseg {

std::uint32_t PlaneFitter::min_triangles() const {
  return 1;
}

PrimitiveFit PlaneFitter::fit(const ClusterView& cluster, double /*error_to_beat*/) const {
  PrimitiveFit result;
  result.valid = true;
  result.primitive.type = PrimitiveType::Plane;
  const Eigen::Vector3d& centroid = cluster.centroid();
  const Eigen::Vector3d& normal_sum = cluster.normal_sum();
  Eigen::Vector3d normal;
  if (cluster.weight() > 0) {
    result.error = std::max(0.0, cluster.smallest_eigenvalue());
    normal = cluster.smallest_eigenvector();
  } else {
    // A cluster of zero-area faces carries no weight: nothing to fit, no error.
    result.error = 0;
    normal = normal_sum.squaredNorm() > 0 ? normal_sum.normalized() : Eigen::Vector3d::UnitZ();
  }
  const double alignment = normal.dot(normal_sum);
  if (alignment < 0 || (alignment == 0 && canonical_axis(normal) != normal)) normal = -normal;
  result.superset_error_bound = result.error;
  if (cluster.area() > 0) result.normal_alignment = normal_sum.norm() / cluster.area();
  result.primitive.point = {centroid.x(), centroid.y(), centroid.z()};
  result.primitive.axis = {normal.x(), normal.y(), normal.z()};
  return result;
}

}  // namespace primseg
