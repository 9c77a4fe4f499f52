#include "marching_tetrahedra.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace primseg::testing {

Mesh marching_tetrahedra(const std::function<double(const Vec3&)>& signed_distance, const Vec3& low,
                         double spacing, const std::array<int, 3>& count) {
  const auto nx = static_cast<std::int64_t>(count[0]) + 1,
             ny = static_cast<std::int64_t>(count[1]) + 1;
  auto node_id = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
  auto node_position = [&](int i, int j, int k) -> Vec3 {
    return {low[0] + spacing * i, low[1] + spacing * j, low[2] + spacing * k};
  };
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;
  std::map<std::pair<std::int64_t, std::int64_t>, std::uint32_t> edge_vertex;

  struct Node {
    std::int64_t id;
    Vec3 p;
    double s;
  };
  auto crossing = [&](const Node& u, const Node& v) {
    const auto key = std::minmax(u.id, v.id);
    const auto found = edge_vertex.find(key);
    if (found != edge_vertex.end()) return found->second;
    const double t = u.s / (u.s - v.s);
    positions.push_back({u.p[0] + t * (v.p[0] - u.p[0]), u.p[1] + t * (v.p[1] - u.p[1]),
                         u.p[2] + t * (v.p[2] - u.p[2])});
    const auto index = static_cast<std::uint32_t>(positions.size() - 1);
    edge_vertex.emplace(key, index);
    return index;
  };
  // Orients a triangle so that its normal points from the inside nodes to the outside ones.
  auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, const Vec3& outward) {
    const Vec3 &pa = positions[a], &pb = positions[b], &pc = positions[c];
    const Vec3 u{pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
    const Vec3 v{pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
    const Vec3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    if (n[0] * outward[0] + n[1] * outward[1] + n[2] * outward[2] >= 0)
      triangles.push_back({a, b, c});
    else
      triangles.push_back({a, c, b});
  };

  constexpr int kAxisOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                     {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < count[2]; ++k)
    for (int j = 0; j < count[1]; ++j)
      for (int i = 0; i < count[0]; ++i)
        for (const auto& order : kAxisOrders) {
          // The path 0 -> e_a -> e_a + e_b -> (1, 1, 1) along the cube's edges.
          std::array<Node, 4> tet;
          std::array<int, 3> offset{0, 0, 0};
          for (int corner = 0; corner < 4; ++corner) {
            if (corner > 0) offset[order[corner - 1]] = 1;
            const int a = i + offset[0], b = j + offset[1], c = k + offset[2];
            const Vec3 p = node_position(a, b, c);
            tet[corner] = {node_id(a, b, c), p, signed_distance(p)};
          }
          std::vector<const Node*> inside, outside;
          for (const Node& node : tet) (node.s < 0 ? inside : outside).push_back(&node);
          if (inside.empty() || outside.empty()) continue;
          Vec3 outward{0, 0, 0};
          for (const Node* node : outside)
            for (int d = 0; d < 3; ++d) outward[d] += node->p[d] / double(outside.size());
          for (const Node* node : inside)
            for (int d = 0; d < 3; ++d) outward[d] -= node->p[d] / double(inside.size());
          if (inside.size() == 1 || outside.size() == 1) {
            const Node* lone = inside.size() == 1 ? inside[0] : outside[0];
            const auto& others = inside.size() == 1 ? outside : inside;
            emit(crossing(*lone, *others[0]), crossing(*lone, *others[1]),
                 crossing(*lone, *others[2]), outward);
          } else {
            const std::uint32_t ac = crossing(*inside[0], *outside[0]);
            const std::uint32_t ad = crossing(*inside[0], *outside[1]);
            const std::uint32_t bd = crossing(*inside[1], *outside[1]);
            const std::uint32_t bc = crossing(*inside[1], *outside[0]);
            emit(ac, ad, bd, outward);
            emit(ac, bd, bc, outward);
          }
        }
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

double box_signed_distance(const Vec3& p, const Vec3& half_extents) {
  double outside2 = 0, inside = -1e300;
  for (int d = 0; d < 3; ++d) {
    const double q = std::abs(p[d]) - half_extents[d];
    outside2 += std::max(q, 0.0) * std::max(q, 0.0);
    inside = std::max(inside, q);
  }
  return std::sqrt(outside2) + std::min(inside, 0.0);
}

Mesh box_mesh(const Vec3& h) {
  std::vector<Vec3> corners;
  for (int c = 0; c < 8; ++c)
    corners.push_back({c & 1 ? h[0] : -h[0], c & 2 ? h[1] : -h[1], c & 4 ? h[2] : -h[2]});
  // Each face as a quad of corner bits, counter-clockwise seen from outside.
  const std::vector<Triangle> triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                           {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                           {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return Mesh::from_triangles(std::move(corners), triangles);
}

}  // namespace primseg::testing
