// Plane: weighted PCA. The normal is the eigenvector of the smallest eigenvalue of the centred
// second moment matrix S, and the L2 error Σ w (n·(x − c))² is exactly that eigenvalue.
#include "primseg/primitives/plane.hpp"

#include <Eigen/Eigenvalues>

namespace primseg {

std::uint32_t PlaneFitter::min_triangles() const {
  return 1;
}

PrimitiveFit PlaneFitter::fit(const ClusterStats& centred) const {
  PrimitiveFit result;
  result.valid = true;
  result.primitive.type = PrimitiveType::Plane;
  const Eigen::Vector3d centroid = centred.moments.origin();
  Eigen::Vector3d normal;
  if (centred.moments.weight() > 0) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(centred.moments.second_moment());
    result.error = std::max(0.0, solver.eigenvalues()(0));
    normal = solver.eigenvectors().col(0);
  } else {
    // A cluster of zero-area faces carries no weight: nothing to fit, no error.
    result.error = 0;
    normal = centred.normal_sum.squaredNorm() > 0 ? centred.normal_sum.normalized()
                                                  : Eigen::Vector3d::UnitZ();
  }
  const double alignment = normal.dot(centred.normal_sum);
  if (alignment < 0 || (alignment == 0 && canonical_axis(normal) != normal)) normal = -normal;
  result.superset_error_bound = result.error;
  if (centred.area > 0) result.normal_alignment = centred.normal_sum.norm() / centred.area;
  result.primitive.point = {centroid.x(), centroid.y(), centroid.z()};
  result.primitive.axis = {normal.x(), normal.y(), normal.z()};
  return result;
}

}  // namespace primseg
