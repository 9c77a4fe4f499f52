#include "skeleton_geometry.hpp"

#include <algorithm>
#include <map>
#include <string>

#include "edge_sides.hpp"
#include "eigen_conversions.hpp"
#include "primseg/error.hpp"
#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg::skeleton_detail {

Vec3 canonical_direction(const Vec3& unit) {
  return detail::to_vec3(canonical_axis(detail::to_eigen(unit)));
}

double distance_to_line(const Vec3& x, const Vec3& point, const Vec3& axis) {
  const Vec3 d = x - point;
  return norm(d - dot(d, axis) * axis);
}

std::vector<ClusterPairBoundary> cluster_pair_boundaries(
    const Mesh& mesh, std::span<const std::uint32_t> triangle_labels) {
  const std::vector<detail::EdgeSide> sides = detail::edge_sides(mesh, triangle_labels);
  std::vector<detail::EdgeSide> scratch;
  std::vector<detail::ClusterLink> links;
  std::map<std::pair<std::uint32_t, std::uint32_t>, ClusterPairBoundary> pairs;
  for (std::size_t begin = 0; begin < sides.size();) {
    const std::size_t end = detail::edge_end(sides, begin);
    const std::uint32_t a = sides[begin].low, b = sides[begin].high;
    const double length = norm(mesh.positions[b] - mesh.positions[a]);
    const Vec3 midpoint = 0.5 * (mesh.positions[a] + mesh.positions[b]);
    links.clear();
    detail::append_cluster_links({sides.data() + begin, end - begin}, scratch, links);
    for (const detail::ClusterLink& link : links) {
      ClusterPairBoundary& boundary = pairs[{link.first.label, link.second.label}];
      boundary.first = link.first.label;
      boundary.second = link.second.label;
      boundary.length += length;
      boundary.weighted_midpoints = boundary.weighted_midpoints + length * midpoint;
      boundary.vertices.push_back(a);
      boundary.vertices.push_back(b);
    }
    begin = end;
  }
  std::vector<ClusterPairBoundary> result;
  result.reserve(pairs.size());
  for (auto& [key, boundary] : pairs) {
    std::sort(boundary.vertices.begin(), boundary.vertices.end());
    boundary.vertices.erase(std::unique(boundary.vertices.begin(), boundary.vertices.end()),
                            boundary.vertices.end());
    result.push_back(std::move(boundary));
  }
  return result;
}

void check_face_labels(const Mesh& mesh, const Skeleton& skeleton, std::string_view caller) {
  if (skeleton.face_labels.size() != mesh.face_count())
    throw InvalidInputError(std::string(caller) + ": the skeleton has " +
                            std::to_string(skeleton.face_labels.size()) + " face labels for " +
                            std::to_string(mesh.face_count()) + " faces");
  for (std::size_t f = 0; f < skeleton.face_labels.size(); ++f)
    if (skeleton.face_labels[f] >= skeleton.bones.size())
      throw InvalidInputError(std::string(caller) + ": face " + std::to_string(f) + " has label " +
                              std::to_string(skeleton.face_labels[f]) + ", not one of the " +
                              std::to_string(skeleton.bones.size()) + " bones");
}

}  // namespace primseg::skeleton_detail
