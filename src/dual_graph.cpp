#include "primseg/dual_graph.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>

namespace primseg {
namespace {

// One directed side of a mesh edge: triangle t traverses it from `from` to `to`.
struct EdgeSide {
  std::uint32_t low, high;  // vertex ids, low < high
  std::uint32_t triangle;
  bool forward;  // traversed low → high
};

struct TriangleLink {
  std::uint32_t first, second;  // triangles
  std::uint32_t low, high;      // the shared edge
};

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<std::uint32_t> parent_;
};

}  // namespace

double WorkingFrame::scale() const {
  return std::ldexp(1.0, exponent);
}

Eigen::Vector3d WorkingFrame::to_working(const Vec3& x) const {
  return {std::ldexp(x[0] - center.x(), -exponent), std::ldexp(x[1] - center.y(), -exponent),
          std::ldexp(x[2] - center.z(), -exponent)};
}

Vec3 WorkingFrame::to_input(const Eigen::Vector3d& x) const {
  return {std::ldexp(x.x(), exponent) + center.x(), std::ldexp(x.y(), exponent) + center.y(),
          std::ldexp(x.z(), exponent) + center.z()};
}

Primitive WorkingFrame::to_input(const Primitive& working) const {
  Primitive p = working;
  p.point = to_input(Eigen::Vector3d(working.point[0], working.point[1], working.point[2]));
  p.radius = std::ldexp(working.radius, exponent);
  p.minor_radius = std::ldexp(working.minor_radius, exponent);
  return p;
}

WorkingFrame working_frame_for(const Mesh& mesh) {
  WorkingFrame frame;
  if (mesh.triangles.empty()) return frame;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Triangle& t : mesh.triangles)
    for (std::uint32_t v : t)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], mesh.positions[v][a]);
        hi[a] = std::max(hi[a], mesh.positions[v][a]);
      }
  // Halving each bound before adding cannot overflow and stays exact for normal numbers.
  frame.center = lo * 0.5 + hi * 0.5;
  const double extent = (hi - frame.center).cwiseMax(frame.center - lo).maxCoeff();
  if (extent > 0) std::frexp(extent, &frame.exponent);
  return frame;
}

DualGraph::DualGraph(const Mesh& mesh, VertexWeights weights)
    : mesh_(&mesh), weights_(weights), frame_(working_frame_for(mesh)) {
  const std::uint32_t triangle_count = mesh.triangle_count();
  const std::uint32_t face_count = mesh.face_count();

  positions_.resize(mesh.positions.size());
  for (std::size_t v = 0; v < positions_.size(); ++v)
    positions_[v] = frame_.to_working(mesh.positions[v]);

  first_triangle_.assign(face_count + 1, 0);
  for (std::uint32_t f : mesh.face_of_triangle) ++first_triangle_[f + 1];
  std::partial_sum(first_triangle_.begin(), first_triangle_.end(), first_triangle_.begin());

  valence_.assign(mesh.positions.size(), 0);
  for (const Triangle& t : mesh.triangles)
    for (std::uint32_t v : t) ++valence_[v];

  // Mesh edges with their triangles, sorted so that each edge's sides are adjacent.
  std::vector<EdgeSide> sides;
  sides.reserve(3 * std::size_t{triangle_count});
  for (std::uint32_t t = 0; t < triangle_count; ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t from = mesh.triangles[t][c], to = mesh.triangles[t][(c + 1) % 3];
      if (from == to) continue;
      sides.push_back({std::min(from, to), std::max(from, to), t, from < to});
    }
  std::sort(sides.begin(), sides.end(), [](const EdgeSide& a, const EdgeSide& b) {
    if (a.low != b.low) return a.low < b.low;
    if (a.high != b.high) return a.high < b.high;
    if (a.triangle != b.triangle) return a.triangle < b.triangle;
    return a.forward < b.forward;
  });

  // Links between consecutive triangles on each edge, and the manifold edges that orient.
  std::vector<TriangleLink> links;
  links.reserve(sides.size() / 2 + 1);
  std::vector<std::uint32_t> orient_offsets(triangle_count + 1, 0);
  std::vector<std::pair<std::uint32_t, std::uint8_t>> orient_neighbours;  // (triangle, must flip)
  std::vector<std::uint8_t> open_triangle(triangle_count, 0);
  struct OrientLink {
    std::uint32_t a, b;
    std::uint8_t flip;
  };
  std::vector<OrientLink> orient_links;
  for (std::size_t begin = 0; begin < sides.size();) {
    std::size_t end = begin + 1;
    while (end < sides.size() && sides[end].low == sides[begin].low &&
           sides[end].high == sides[begin].high)
      ++end;
    const std::size_t k = end - begin;
    if (k == 2 && sides[begin].triangle != sides[begin + 1].triangle) {
      // Consistent neighbours traverse their shared edge in opposite directions.
      orient_links.push_back(
          {sides[begin].triangle, sides[begin + 1].triangle,
           static_cast<std::uint8_t>(sides[begin].forward == sides[begin + 1].forward)});
    } else {
      for (std::size_t s = begin; s < end; ++s) open_triangle[sides[s].triangle] = 1;
    }
    for (std::size_t s = begin; s + 1 < end; ++s)
      if (sides[s].triangle != sides[s + 1].triangle)
        links.push_back(
            {sides[s].triangle, sides[s + 1].triangle, sides[begin].low, sides[begin].high});
    begin = end;
  }
  std::vector<EdgeSide>().swap(sides);

  // Orientation: breadth-first over manifold edges from the lowest unvisited triangle.
  for (const OrientLink& l : orient_links) {
    ++orient_offsets[l.a + 1];
    ++orient_offsets[l.b + 1];
  }
  std::partial_sum(orient_offsets.begin(), orient_offsets.end(), orient_offsets.begin());
  orient_neighbours.resize(orient_offsets.back());
  {
    std::vector<std::uint32_t> fill(orient_offsets.begin(), orient_offsets.end() - 1);
    for (const OrientLink& l : orient_links) {
      orient_neighbours[fill[l.a]++] = {l.b, l.flip};
      orient_neighbours[fill[l.b]++] = {l.a, l.flip};
    }
  }
  flipped_.assign(triangle_count, 0);
  std::vector<std::uint32_t> orient_component(triangle_count, UINT32_MAX);
  std::vector<std::uint32_t> queue;
  std::vector<std::uint8_t> component_open;
  for (std::uint32_t seed = 0; seed < triangle_count; ++seed) {
    if (orient_component[seed] != UINT32_MAX) continue;
    const auto component = static_cast<std::uint32_t>(component_open.size());
    component_open.push_back(0);
    orient_component[seed] = component;
    queue.assign(1, seed);
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::uint32_t t = queue[head];
      component_open[component] |= open_triangle[t];
      for (std::uint32_t n = orient_offsets[t]; n < orient_offsets[t + 1]; ++n) {
        const auto [other, flip] = orient_neighbours[n];
        const std::uint8_t wanted = flipped_[t] ^ flip;
        if (orient_component[other] == UINT32_MAX) {
          orient_component[other] = component;
          flipped_[other] = wanted;
          queue.push_back(other);
        } else if (flipped_[other] != wanted) {
          component_open[component] = 1;  // not orientable (a Möbius band): no inside
        }
      }
    }
  }
  // Closed components face outward: flip those of negative signed volume.
  std::vector<double> volume(component_open.size(), 0.0);
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    const Triangle& tri = mesh.triangles[t];
    const double v = positions_[tri[0]].dot(positions_[tri[1]].cross(positions_[tri[2]]));
    volume[orient_component[t]] += flipped_[t] ? -v : v;
  }
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    const std::uint32_t c = orient_component[t];
    if (!component_open[c] && volume[c] < 0) flipped_[t] ^= 1;
  }

  // Signed dihedral angles of the links.
  auto oriented_normal = [&](std::uint32_t t) {
    const Triangle& tri = mesh.triangles[t];
    const Eigen::Vector3d n =
        (positions_[tri[1]] - positions_[tri[0]]).cross(positions_[tri[2]] - positions_[tri[0]]);
    return flipped_[t] ? Eigen::Vector3d(-n) : n;
  };
  std::vector<DualEdge> records;
  records.reserve(links.size());
  for (const TriangleLink& link : links) {
    const Eigen::Vector3d n1 = oriented_normal(link.first), n2 = oriented_normal(link.second);
    const Eigen::Vector3d edge = positions_[link.high] - positions_[link.low];
    double beta = 0;
    std::uint32_t opposite = UINT32_MAX;
    for (std::uint32_t v : mesh.triangles[link.second])
      if (v != link.low && v != link.high) opposite = v;
    if (opposite != UINT32_MAX && n1.squaredNorm() > 0 && n2.squaredNorm() > 0) {
      // atan2 keeps full precision near 0 where acos of the dot product would not.
      beta = std::atan2(n1.cross(n2).norm(), n1.dot(n2));
      if ((positions_[opposite] - positions_[link.low]).dot(n1) > 0) beta = -beta;
    }
    EdgeStats stats;
    stats.add_edge(edge, beta);
    const std::uint32_t fa = mesh.face_of_triangle[link.first];
    const std::uint32_t fb = mesh.face_of_triangle[link.second];
    if (fa == fb)
      internal_edges_.push_back({fa, stats});
    else
      records.push_back({std::min(fa, fb), std::max(fa, fb), stats});
  }
  std::vector<TriangleLink>().swap(links);

  auto by_faces = [](const DualEdge& a, const DualEdge& b) {
    return a.first != b.first ? a.first < b.first : a.second < b.second;
  };
  // Stable: the tensor sums below then add in a fixed order.
  std::stable_sort(records.begin(), records.end(), by_faces);
  for (const DualEdge& r : records) {
    if (!edges_.empty() && edges_.back().first == r.first && edges_.back().second == r.second) {
      edges_.back().shared += r.shared;
    } else {
      edges_.push_back(r);
    }
  }
  std::stable_sort(internal_edges_.begin(), internal_edges_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });

  UnionFind components(face_count);
  for (const DualEdge& e : edges_) components.unite(e.first, e.second);
  component_of_face_.resize(face_count);
  std::vector<std::uint32_t> number(face_count, UINT32_MAX);
  for (std::uint32_t f = 0; f < face_count; ++f) {
    const std::uint32_t root = components.find(f);
    if (number[root] == UINT32_MAX) number[root] = component_count_++;
    component_of_face_[f] = number[root];
  }
}

double DualGraph::triangle_area(std::uint32_t t) const {
  const Triangle& tri = mesh_->triangles[t];
  return 0.5 * (positions_[tri[1]] - positions_[tri[0]])
                   .cross(positions_[tri[2]] - positions_[tri[0]])
                   .norm();
}

void DualGraph::prefetch_face(std::uint32_t f) const {
  __builtin_prefetch(&first_triangle_[f]);
  // Most faces are one triangle, and face f's is then triangle f when all are.
  if (first_triangle_.size() == mesh_->triangles.size() + 1)
    __builtin_prefetch(&mesh_->triangles[f]);
}

void DualGraph::prefetch_face_corners(std::uint32_t f) const {
  for (std::uint32_t t = first_triangle_[f]; t < first_triangle_[f + 1]; ++t)
    for (std::uint32_t v : mesh_->triangles[t]) __builtin_prefetch(&positions_[v]);
}

std::array<double, 3> DualGraph::corner_weights(std::uint32_t t) const {
  return corner_weights(t, weights_ == VertexWeights::Area ? triangle_area(t) : 0.0);
}

std::array<double, 3> DualGraph::corner_weights(std::uint32_t t, double area) const {
  const Triangle& tri = mesh_->triangles[t];
  if (weights_ == VertexWeights::Uniform)
    return {1.0 / valence_[tri[0]], 1.0 / valence_[tri[1]], 1.0 / valence_[tri[2]]};
  return {area / 3, area / 3, area / 3};
}

ClusterStats DualGraph::face_stats(std::uint32_t f, bool with_samples, int max_degree) const {
  ClusterStats stats;
  face_stats(f, stats, with_samples, max_degree);
  return stats;
}

void DualGraph::face_stats(std::uint32_t f, ClusterStats& stats, bool with_samples,
                           int max_degree) const {
  const std::uint32_t begin = first_triangle_[f], end = first_triangle_[f + 1];
  // Area vectors and corner weights first: the moments are taken about the weighted centroid of
  // the corners (the first triangle's centroid if they weigh nothing), so that the statistics are
  // centred as the fitters and unions expect. Most faces are one triangle.
  struct Corners {
    Eigen::Vector3d normal;  // oriented, length twice the area
    std::array<double, 3> weights;
  };
  constexpr std::uint32_t kInline = 4;
  std::array<Corners, kInline> inline_corners;
  std::vector<Corners> many;
  Corners* corners = inline_corners.data();
  if (end - begin > kInline) {
    many.resize(end - begin);
    corners = many.data();
  }
  Eigen::Vector3d weighted_sum = Eigen::Vector3d::Zero();
  double weight = 0;
  for (std::uint32_t t = begin; t < end; ++t) {
    const Triangle& tri = mesh_->triangles[t];
    Corners& c = corners[t - begin];
    c.normal =
        (positions_[tri[1]] - positions_[tri[0]]).cross(positions_[tri[2]] - positions_[tri[0]]);
    if (flipped_[t]) c.normal = -c.normal;
    c.weights = corner_weights(t, 0.5 * c.normal.norm());
    for (int k = 0; k < 3; ++k) {
      weighted_sum += c.weights[k] * positions_[tri[k]];
      weight += c.weights[k];
    }
  }
  if (weight > 0) {
    stats.moments = Moments(weighted_sum / weight);
  } else {
    const Triangle& first = mesh_->triangles[begin];
    stats.moments =
        Moments((positions_[first[0]] + positions_[first[1]] + positions_[first[2]]) / 3);
  }
  stats.edges = {};
  stats.normal_sum.setZero();
  stats.normal_position.setZero();
  stats.face_planes = {};
  stats.area = 0;
  stats.triangle_count = 0;
  stats.samples.samples.clear();
  for (std::uint32_t t = begin; t < end; ++t) {
    const Triangle& tri = mesh_->triangles[t];
    const Corners& c = corners[t - begin];
    for (int k = 0; k < 3; ++k)
      stats.moments.add_point(positions_[tri[k]], c.weights[k], max_degree);
    const Eigen::Vector3d& n = c.normal;
    const Eigen::Vector3d centroid =
        (positions_[tri[0]] + positions_[tri[1]] + positions_[tri[2]]) / 3;
    stats.normal_position += (centroid - stats.moments.origin()) * (0.5 * n).transpose();
    stats.normal_sum += 0.5 * n;
    const double area = 0.5 * n.norm();
    if (area > 0)
      stats.face_planes.add_face(n / (2 * area), area, centroid - stats.moments.origin());
    if (with_samples) {
      const Eigen::Vector3f unit =
          area > 0 ? Eigen::Vector3f((n / (2 * area)).cast<float>()) : Eigen::Vector3f::Zero();
      for (int k = 0; k < 3; ++k)
        stats.samples.add({positions_[tri[k]], unit, (centroid - positions_[tri[k]]).cast<float>(),
                           c.weights[k],
                           SampleReservoir::priority_of(std::uint64_t{t} * 3 + k, c.weights[k])});
    }
    stats.area += area;
    ++stats.triangle_count;
  }
  auto it =
      std::lower_bound(internal_edges_.begin(), internal_edges_.end(), f,
                       [](const auto& entry, std::uint32_t face) { return entry.first < face; });
  for (; it != internal_edges_.end() && it->first == f; ++it) stats.edges += it->second;
  stats.moments.discard_first_moments();
}

}  // namespace primseg
