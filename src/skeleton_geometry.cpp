#include "skeleton_geometry.hpp"

#include <algorithm>
#include <map>

#include "eigen_conversions.hpp"
#include "primseg/primitives/primitive_fitter.hpp"

namespace primseg::skeleton_detail {

Vec3 canonical_direction(const Vec3& unit) {
  return detail::to_vec3(canonical_axis(detail::to_eigen(unit)));
}

double distance_to_line(const Vec3& x, const Vec3& point, const Vec3& axis) {
  const Vec3 d = x - point;
  return norm(d - dot(d, axis) * axis);
}

std::vector<std::uint32_t> triangle_labels(const Mesh& mesh,
                                           std::span<const std::uint32_t> face_labels) {
  std::vector<std::uint32_t> labels(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    labels[t] = face_labels[mesh.face_of_triangle[t]];
  return labels;
}

std::vector<ClusterPairBoundary> cluster_pair_boundaries(
    const Mesh& mesh, std::span<const std::uint32_t> triangle_labels) {
  // Every edge with the cluster of each of its triangles: sorted, an edge's entries are
  // consecutive.
  struct EdgeEntry {
    std::uint32_t low, high, label;
    // NOLINTNEXTLINE(modernize-use-nullptr): clang-tidy 14 misreads the defaulted <=>.
    auto operator<=>(const EdgeEntry&) const = default;
  };
  std::vector<EdgeEntry> entries;
  entries.reserve(3 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = tri[e], b = tri[(e + 1) % 3];
      if (a != b) entries.push_back({std::min(a, b), std::max(a, b), triangle_labels[t]});
    }
  }
  std::sort(entries.begin(), entries.end());
  entries.erase(std::unique(entries.begin(), entries.end()), entries.end());

  std::map<std::pair<std::uint32_t, std::uint32_t>, ClusterPairBoundary> pairs;
  for (std::size_t begin = 0; begin < entries.size();) {
    std::size_t end = begin + 1;
    while (end < entries.size() && entries[end].low == entries[begin].low &&
           entries[end].high == entries[begin].high)
      ++end;
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

}  // namespace primseg::skeleton_detail
