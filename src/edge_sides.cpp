#include "edge_sides.hpp"

#include <algorithm>
#include <utility>

namespace primseg::detail {

std::vector<std::uint32_t> triangle_labels(const Mesh& mesh,
                                           std::span<const std::uint32_t> face_labels) {
  std::vector<std::uint32_t> labels(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    labels[t] = face_labels[mesh.face_of_triangle[t]];
  return labels;
}

std::vector<EdgeSide> edge_sides(const Mesh& mesh, std::span<const std::uint32_t> triangle_labels) {
  std::vector<EdgeSide> sides;
  sides.reserve(3 * mesh.triangles.size());
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = tri[e], b = tri[(e + 1) % 3];
      if (a != b) sides.push_back({std::min(a, b), std::max(a, b), triangle_labels[t], t});
    }
  }
  std::sort(sides.begin(), sides.end());
  return sides;
}

std::size_t edge_end(std::span<const EdgeSide> sides, std::size_t begin) {
  std::size_t end = begin + 1;
  while (end < sides.size() && sides[end].low == sides[begin].low &&
         sides[end].high == sides[begin].high)
    ++end;
  return end;
}

void append_cluster_links(std::span<const EdgeSide> edge, std::vector<EdgeSide>& scratch,
                          std::vector<ClusterLink>& links) {
  if (edge.size() == 2) {  // sorted by label already
    if (edge[0].label != edge[1].label) links.push_back({edge[0], edge[1]});
    return;
  }
  scratch.assign(edge.begin(), edge.end());
  std::sort(scratch.begin(), scratch.end(),
            [](const EdgeSide& a, const EdgeSide& b) { return a.triangle < b.triangle; });
  const auto first_new = static_cast<std::ptrdiff_t>(links.size());
  for (std::size_t i = 0; i + 1 < scratch.size(); ++i) {
    const EdgeSide& a = scratch[i];
    const EdgeSide& b = scratch[i + 1];
    if (a.label != b.label)
      links.push_back(a.label < b.label ? ClusterLink{a, b} : ClusterLink{b, a});
  }
  const auto labels = [](const ClusterLink& link) {
    return std::pair(link.first.label, link.second.label);
  };
  // Stable: the first link of each pair stays.
  std::stable_sort(
      links.begin() + first_new, links.end(),
      [&](const ClusterLink& a, const ClusterLink& b) { return labels(a) < labels(b); });
  links.erase(std::unique(links.begin() + first_new, links.end(),
                          [&](const ClusterLink& a, const ClusterLink& b) {
                            return labels(a) == labels(b);
                          }),
              links.end());
}

}  // namespace primseg::detail
