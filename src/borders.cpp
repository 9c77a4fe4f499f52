#include "primseg/borders.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <tuple>

#include "edge_sides.hpp"
#include "no_index.hpp"
#include "primseg/error.hpp"
#include "shape_generator/vector_math.hpp"

namespace primseg {
namespace {

using detail::EdgeSide;
using detail::kNone;
using namespace shape_detail;  // Vec3 -, cross, dot, norm

// One mesh edge of one border, with the two linked triangles of its clusters on it.
struct BorderEdge {
  std::uint32_t first, second, low, high;
  std::uint32_t first_triangle, second_triangle;  // kNone on the mesh boundary's side
  bool operator<(const BorderEdge& other) const {
    return std::tie(first, second, low, high) <
           std::tie(other.first, other.second, other.low, other.high);
  }
};

bool same_border(const BorderEdge& a, const BorderEdge& b) {
  return a.first == b.first && a.second == b.second;
}

void check_inputs(const Mesh& mesh, std::span<const std::uint32_t> face_labels,
                  std::span<const Primitive> primitives) {
  mesh.validate();
  if (face_labels.size() != mesh.face_count())
    throw InvalidInputError("cluster borders: " + std::to_string(face_labels.size()) +
                            " labels for " + std::to_string(mesh.face_count()) + " faces");
  for (const std::uint32_t label : face_labels) {
    if (label == kMeshBoundary)
      throw InvalidInputError("cluster borders: label " + std::to_string(label) +
                              " is reserved for the mesh boundary");
    if (!primitives.empty() && label >= primitives.size())
      throw InvalidInputError("cluster borders: label " + std::to_string(label) +
                              " out of range (" + std::to_string(primitives.size()) +
                              " primitives)");
  }
}

// Every edge of every border, sorted by border, then edge.
std::vector<BorderEdge> border_edges(const Mesh& mesh, std::span<const std::uint32_t> face_labels) {
  const std::vector<EdgeSide> sides =
      detail::edge_sides(mesh, detail::triangle_labels(mesh, face_labels));
  std::vector<BorderEdge> edges;
  std::vector<EdgeSide> scratch;
  std::vector<detail::ClusterLink> links;
  for (std::size_t begin = 0; begin < sides.size();) {
    const std::size_t end = detail::edge_end(sides, begin);
    const std::uint32_t low = sides[begin].low, high = sides[begin].high;
    if (end - begin == 1)
      edges.push_back({sides[begin].label, kMeshBoundary, low, high, sides[begin].triangle, kNone});
    links.clear();
    detail::append_cluster_links({sides.data() + begin, end - begin}, scratch, links);
    for (const detail::ClusterLink& link : links)
      edges.push_back({link.first.label, link.second.label, low, high, link.first.triangle,
                       link.second.triangle});
    begin = end;
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

// Triangle t's normal scaled by twice its area, its corners taken as listed.
Vec3 listed_normal(const Mesh& mesh, std::uint32_t t) {
  const Triangle& c = mesh.triangles[t];
  return cross(mesh.positions[c[1]] - mesh.positions[c[0]],
               mesh.positions[c[2]] - mesh.positions[c[0]]);
}

// +1 when triangle t runs along its edge (low, high) from `low` to `high`, −1 the other way.
int direction_along(const Mesh& mesh, std::uint32_t t, std::uint32_t low, std::uint32_t high) {
  const Triangle& c = mesh.triangles[t];
  for (int e = 0; e < 3; ++e)
    if (c[e] == low && c[(e + 1) % 3] == high) return 1;
  return -1;
}

// The angle, in degrees, between the two clusters' primitives across one border edge; NaN when a
// triangle on it has zero area.
double edge_angle(const Mesh& mesh, const BorderEdge& edge, std::span<const Primitive> primitives) {
  Vec3 first_normal = listed_normal(mesh, edge.first_triangle);
  Vec3 second_normal = listed_normal(mesh, edge.second_triangle);
  if (!(norm(first_normal) > 0 && norm(second_normal) > 0))
    return std::numeric_limits<double>::quiet_NaN();
  // Consistently oriented triangles run along their common edge in opposite directions.
  if (direction_along(mesh, edge.first_triangle, edge.low, edge.high) ==
      direction_along(mesh, edge.second_triangle, edge.low, edge.high))
    second_normal = -1.0 * second_normal;
  const Vec3 midpoint = 0.5 * (mesh.positions[edge.low] + mesh.positions[edge.high]);
  const auto oriented = [&midpoint](const Primitive& primitive, const Vec3& like) {
    const Vec3 n = primitive.normal(midpoint);
    return dot(n, like) < 0 ? -1.0 * n : n;
  };
  const Vec3 a = oriented(primitives[edge.first], first_normal);
  const Vec3 b = oriented(primitives[edge.second], second_normal);
  // π × (180 / π) rounds to a little above 180.
  return std::min(180.0, std::atan2(norm(cross(a, b)), dot(a, b)) * (180 / std::numbers::pi));
}

// The curves of one border's edges (sorted by (low, high)). `junction[v]` marks the vertices where
// another border meets some border.
std::vector<BorderCurve> chain(std::span<const BorderEdge> edges,
                               const std::vector<bool>& junction) {
  // Each edge at both its ends, sorted by vertex: a vertex's edges are consecutive.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> incident;  // (vertex, edge)
  incident.reserve(2 * edges.size());
  for (std::uint32_t e = 0; e < edges.size(); ++e) {
    incident.emplace_back(edges[e].low, e);
    incident.emplace_back(edges[e].high, e);
  }
  std::sort(incident.begin(), incident.end());
  // The distinct vertices, and where each one's edges start in `incident`: a lookup is a binary
  // search, so a vertex on d edges costs O(d log) and not O(d²) (a book's spine).
  std::vector<std::uint32_t> vertices, first_incident;
  for (std::uint32_t i = 0; i < incident.size(); ++i)
    if (i == 0 || incident[i].first != incident[i - 1].first) {
      vertices.push_back(incident[i].first);
      first_incident.push_back(i);
    }
  first_incident.push_back(static_cast<std::uint32_t>(incident.size()));
  const auto edges_at_index = [&](std::size_t k) {
    return std::span<const std::pair<std::uint32_t, std::uint32_t>>(
        incident.data() + first_incident[k], first_incident[k + 1] - first_incident[k]);
  };
  const auto edges_at = [&](std::uint32_t v) {
    return edges_at_index(static_cast<std::size_t>(
        std::lower_bound(vertices.begin(), vertices.end(), v) - vertices.begin()));
  };
  const auto ends_here = [&](std::uint32_t v) { return junction[v] || edges_at(v).size() != 2; };
  const auto other_end = [&edges](std::uint32_t e, std::uint32_t v) {
    return edges[e].low == v ? edges[e].high : edges[e].low;
  };

  std::vector<bool> used(edges.size(), false);
  // Follows edge e from `start` until an end of a curve, or back to `start`.
  const auto follow = [&](std::uint32_t start, std::uint32_t e) {
    BorderCurve curve;
    curve.vertices.push_back(start);
    std::uint32_t at = start;
    while (true) {
      used[e] = true;
      at = other_end(e, at);
      if (at == start) {
        curve.closed = true;
        break;
      }
      curve.vertices.push_back(at);
      if (ends_here(at)) break;
      const auto around = edges_at(at);
      e = around[0].second == e ? around[1].second : around[0].second;
      if (used[e]) break;
    }
    return curve;
  };

  std::vector<BorderCurve> curves;
  for (std::size_t k = 0; k < vertices.size(); ++k) {
    const std::uint32_t v = vertices[k];
    if (!ends_here(v)) continue;
    for (const auto& entry : edges_at_index(k))
      if (!used[entry.second]) curves.push_back(follow(v, entry.second));
  }
  for (std::uint32_t e = 0; e < edges.size(); ++e)
    if (!used[e]) curves.push_back(follow(edges[e].low, e));
  return curves;
}

}  // namespace

std::vector<ClusterBorder> cluster_borders(const Mesh& mesh,
                                           std::span<const std::uint32_t> face_labels,
                                           std::span<const Primitive> primitives) {
  check_inputs(mesh, face_labels, primitives);
  const std::vector<BorderEdge> edges = border_edges(mesh, face_labels);

  // A vertex on the edges of two borders or more is a corner of each.
  std::vector<bool> junction(mesh.vertex_count(), false);
  {
    std::vector<std::size_t> border_at(mesh.vertex_count(), edges.size());  // first edge's border
    std::size_t border = 0;
    for (std::size_t i = 0; i < edges.size(); ++i) {
      if (i > 0 && !same_border(edges[i], edges[i - 1])) ++border;
      for (const std::uint32_t v : {edges[i].low, edges[i].high}) {
        if (border_at[v] == edges.size())
          border_at[v] = border;
        else if (border_at[v] != border)
          junction[v] = true;
      }
    }
  }

  std::vector<ClusterBorder> borders;
  for (std::size_t begin = 0; begin < edges.size();) {
    std::size_t end = begin + 1;
    while (end < edges.size() && same_border(edges[end], edges[begin])) ++end;
    const std::span<const BorderEdge> own(edges.data() + begin, end - begin);
    ClusterBorder border;
    border.first = own.front().first;
    border.second = own.front().second;
    border.edge_count = static_cast<std::uint32_t>(own.size());
    double angle_sum = 0, angle_weight = 0;
    for (const BorderEdge& edge : own) {
      const double length = norm(mesh.positions[edge.high] - mesh.positions[edge.low]);
      border.length += length;
      if (primitives.empty() || border.second == kMeshBoundary) continue;
      const double angle = edge_angle(mesh, edge, primitives);
      if (std::isnan(angle)) continue;
      angle_sum += length * angle;
      angle_weight += length;
    }
    if (angle_weight > 0) border.angle = std::min(180.0, angle_sum / angle_weight);
    border.curves = chain(own, junction);
    borders.push_back(std::move(border));
    begin = end;
  }
  return borders;
}

}  // namespace primseg
