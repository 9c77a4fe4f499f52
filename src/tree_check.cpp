#include "tree_check.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "face_adjacency.hpp"
#include "no_index.hpp"
#include "primseg/error.hpp"

namespace primseg::detail {
namespace {

bool finite_non_negative(double x) {
  return std::isfinite(x) && x >= 0;
}

// Lengths beyond this many working units (the mesh spans about 2) are no fit of it: their squares
// would overflow the reports' distances. The same bounds a node's RMS error.
constexpr double kMaxWorkingLength = 1e30;
// Costs only order merges; this leaves room above the largest for SciPy's strictly increasing
// heights (cut.hpp, scipy_linkage).
constexpr double kMaxCost = 1e300;
// A node's weight is the sum of its faces' corner weights, summed in another order by the builder.
constexpr double kWeightTolerance = 1e-9;

bool valid_primitive(const Primitive& p, const WorkingFrame& frame) {
  const Eigen::Vector3d point = frame.to_working(p.point);
  const double scale = frame.scale();
  if (!point.allFinite() || point.lpNorm<Eigen::Infinity>() > kMaxWorkingLength) return false;
  for (const double radius : {p.radius, p.minor_radius})
    if (!finite_non_negative(radius) || radius / scale > kMaxWorkingLength) return false;
  if (!std::isfinite(p.half_angle)) return false;
  if (p.type == PrimitiveType::Sphere) return true;  // the only type without an axis
  const double length = std::hypot(p.axis[0], p.axis[1], p.axis[2]);
  return std::abs(length - 1) <= 1e-9;
}

[[noreturn]] void reject(std::size_t merge, const std::string& why) {
  throw InvalidInputError("merge " + std::to_string(merge) + " " + why);
}

}  // namespace

void check_tree_parts(const DualGraph& graph, const HierarchyOptions& options,
                      std::span<const Merge> merges) {
  const std::uint32_t f = graph.face_count();
  const FaceAdjacency adjacency(graph);
  // Live clusters as linked lists of faces with their face count and weight; a face's label is
  // its cluster's list. Merging relabels the smaller list, so each face is relabelled (and its
  // neighbours read) O(log F) times.
  std::vector<std::uint32_t> label(f), next_face(f, kNone), head(f), tail(f), size(f, 1);
  std::vector<double> list_weight(f, 0);
  for (std::uint32_t face = 0; face < f; ++face)
    for (std::uint32_t t = graph.first_triangle(face); t < graph.first_triangle(face + 1); ++t)
      for (const double w : graph.corner_weights(t)) list_weight[face] += w;
  std::vector<std::uint32_t> list_of_node(2 * std::size_t{f} - 1, kNone);
  std::iota(label.begin(), label.end(), 0u);
  std::iota(head.begin(), head.end(), 0u);
  std::iota(tail.begin(), tail.end(), 0u);
  std::iota(list_of_node.begin(), list_of_node.begin() + f, 0u);

  const std::uint32_t real_count = f - graph.component_count();
  for (std::size_t i = 0; i < merges.size(); ++i) {
    const Merge& m = merges[i];
    if (m.first >= m.second) reject(i, "must give its children as first < second");
    std::uint32_t a = list_of_node[m.first], b = list_of_node[m.second];
    if (m.face_count != size[a] + size[b])
      reject(i, "has " + std::to_string(m.face_count) + " faces, its children " +
                    std::to_string(size[a] + size[b]));
    if (!finite_non_negative(m.cost) || !finite_non_negative(m.error) ||
        !finite_non_negative(m.weight))
      reject(i, "has a negative or non-finite cost, error or weight");
    const double weight = list_weight[a] + list_weight[b];
    if (std::abs(m.weight - weight) > kWeightTolerance * weight)
      reject(i, "has a weight that is not the sum of its faces' weights");
    if (m.cost > kMaxCost || m.error > m.weight * (kMaxWorkingLength * kMaxWorkingLength))
      reject(i, "has a cost above 1e300 or an RMS error above 1e30 working units");
    if (m.trailing != (i >= real_count))
      reject(i, std::string(m.trailing ? "is trailing" : "is not trailing") + ": the mesh's " +
                    std::to_string(graph.component_count()) + " components need " +
                    std::to_string(real_count) + " real merges, then trailing ones");
    if (size[a] < size[b]) std::swap(a, b);  // b is the smaller list
    if (!m.trailing) {
      if (std::find(options.primitives.begin(), options.primitives.end(), m.primitive.type) ==
          options.primitives.end())
        reject(i, "has a primitive of a type the tree's options do not enable");
      if (!valid_primitive(m.primitive, graph.frame()))
        reject(i,
               "has an invalid primitive: non-finite or huge parameters, a negative radius or a "
               "non-unit axis");
      bool adjacent = false;
      for (std::uint32_t x = head[b]; x != kNone && !adjacent; x = next_face[x])
        for (std::uint32_t k = adjacency.offset[x]; k < adjacency.offset[x + 1] && !adjacent; ++k)
          adjacent = label[adjacency.neighbour[k]] == a;
      if (!adjacent) reject(i, "joins two clusters that share no mesh edge");
    }
    for (std::uint32_t x = head[b]; x != kNone; x = next_face[x]) label[x] = a;
    next_face[tail[a]] = head[b];
    tail[a] = tail[b];
    size[a] += size[b];
    list_weight[a] = weight;
    list_of_node[f + i] = a;
  }
}

}  // namespace primseg::detail
