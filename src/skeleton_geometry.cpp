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
  // Every edge with the clusters of its triangles, each cluster once.
  std::vector<detail::EdgeSide> entries = detail::edge_sides(mesh, triangle_labels);
  entries.erase(std::unique(entries.begin(), entries.end(),
                            [](const detail::EdgeSide& a, const detail::EdgeSide& b) {
                              return a.low == b.low && a.high == b.high && a.label == b.label;
                            }),
                entries.end());

  std::map<std::pair<std::uint32_t, std::uint32_t>, ClusterPairBoundary> pairs;
  for (std::size_t begin = 0; begin < entries.size();) {
    const std::size_t end = detail::edge_end(entries, begin);
    const std::uint32_t a = entries[begin].low, b = entries[begin].high;
    const double length = norm(mesh.positions[b] - mesh.positions[a]);
    const Vec3 midpoint = 0.5 * (mesh.positions[a] + mesh.positions[b]);
    for (std::size_t i = begin; i < end; ++i)
      for (std::size_t j = i + 1; j < end; ++j) {
        ClusterPairBoundary& boundary = pairs[{entries[i].label, entries[j].label}];
        boundary.first = entries[i].label;
        boundary.second = entries[j].label;
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
