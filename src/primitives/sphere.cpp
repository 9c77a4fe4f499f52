// Sphere: Pratt's constrained algebraic fit (pratt_fit.hpp) from the centred moments up to degree
// 4. Its error, Σ w (|x − c|² − r²)² / (4r²), is the exact minimum of that normalised algebraic
// distance over all spheres and a first-order equivalent of Σ w (|x − c| − r)².
#include "primseg/primitives/sphere.hpp"

#include "primitives/pratt_fit.hpp"

namespace primseg {

std::uint32_t SphereFitter::min_triangles() const {
  return 4;
}

PrimitiveFit SphereFitter::fit(const ClusterView& cluster, double error_to_beat) const {
  PrimitiveFit result;
  result.primitive.type = PrimitiveType::Sphere;
  if (cluster.triangle_count() < min_triangles()) return result;
  const detail::PrattResult<3> sphere = detail::pratt_fit(cluster, error_to_beat);
  result.superset_error_bound = sphere.objective_minimum;
  result.beaten = sphere.beaten;
  if (!sphere.valid) return result;
  const Eigen::Vector3d centre = cluster.centroid() + sphere.centre;
  result.normal_alignment =
      cluster.normal_alignment(Eigen::Matrix3d::Identity(), centre, sphere.radius);
  if (result.normal_alignment < kMinNormalAlignment) return result;
  result.valid = true;
  result.error = sphere.error;
  result.primitive.point = {centre.x(), centre.y(), centre.z()};
  result.primitive.radius = sphere.radius;
  return result;
}

}  // namespace primseg
