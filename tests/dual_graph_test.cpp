// The dual graph equals, bit for bit, a reference built the straightforward way (a comparison sort
// of all triangle sides, then a stable sort of all links by face pair): on generated solids, real
// scans, shuffled meshes, polygon faces, non-manifold edges, several open and closed components,
// non-orientable surfaces, degenerate and duplicate triangles.
#include "primseg/dual_graph.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>
#include <string>
#include <tuple>

#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

// What DualGraph's constructor computes, by the algorithm it first used (kept as the reference).
// Of the three rotations of a triangle's corners, the one that lists first the corner with the
// smallest (x, y, z, index), compared as a whole tuple.
Triangle canonical_rotation(const Triangle& tri, const std::vector<Eigen::Vector3d>& positions) {
  auto key = [&](std::uint32_t v) {
    return std::make_tuple(positions[v].x(), positions[v].y(), positions[v].z(), v);
  };
  const int first = static_cast<int>(
      std::min_element(tri.begin(), tri.end(),
                       [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); }) -
      tri.begin());
  return {tri[first], tri[(first + 1) % 3], tri[(first + 2) % 3]};
}

struct ReferenceGraph {
  std::vector<Eigen::Vector3d> positions;
  std::vector<std::uint32_t> first_triangle;
  std::vector<std::uint8_t> flipped;
  std::vector<std::uint32_t> valence;
  std::vector<std::uint32_t> component_of_face;
  std::uint32_t component_count = 0;
  std::vector<DualEdge> edges;
  std::vector<std::pair<std::uint32_t, EdgeStats>> internal_edges;
};

ReferenceGraph reference_graph(const Mesh& mesh) {
  struct EdgeSide {
    std::uint32_t low, high;  // vertex ids, low < high
    std::uint32_t triangle;
    bool forward;  // traversed low → high
  };
  struct TriangleLink {
    std::uint32_t first, second;  // triangles
    std::uint32_t low, high;      // the shared edge
  };
  ReferenceGraph g;
  const WorkingFrame frame = working_frame_for(mesh);
  const std::uint32_t triangle_count = mesh.triangle_count();
  const std::uint32_t face_count = mesh.face_count();

  g.positions.resize(mesh.positions.size());
  for (std::size_t v = 0; v < g.positions.size(); ++v)
    g.positions[v] = frame.to_working(mesh.positions[v]);

  g.first_triangle.assign(face_count + 1, 0);
  for (std::uint32_t f : mesh.face_of_triangle) ++g.first_triangle[f + 1];
  std::partial_sum(g.first_triangle.begin(), g.first_triangle.end(), g.first_triangle.begin());

  g.valence.assign(mesh.positions.size(), 0);
  for (const Triangle& t : mesh.triangles)
    for (std::uint32_t v : t) ++g.valence[v];

  std::vector<EdgeSide> sides;
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

  std::vector<TriangleLink> links;
  std::vector<std::uint32_t> orient_offsets(triangle_count + 1, 0);
  std::vector<std::pair<std::uint32_t, std::uint8_t>> orient_neighbours;
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
    if (end - begin == 2 && sides[begin].triangle != sides[begin + 1].triangle) {
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
  g.flipped.assign(triangle_count, 0);
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
        const std::uint8_t wanted = g.flipped[t] ^ flip;
        if (orient_component[other] == UINT32_MAX) {
          orient_component[other] = component;
          g.flipped[other] = wanted;
          queue.push_back(other);
        } else if (g.flipped[other] != wanted) {
          component_open[component] = 1;
        }
      }
    }
  }
  std::vector<double> volume(component_open.size(), 0.0);
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    const Triangle tri = canonical_rotation(mesh.triangles[t], g.positions);
    const double v = g.positions[tri[0]].dot(g.positions[tri[1]].cross(g.positions[tri[2]]));
    volume[orient_component[t]] += g.flipped[t] ? -v : v;
  }
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    const std::uint32_t c = orient_component[t];
    if (!component_open[c] && volume[c] < 0) g.flipped[t] ^= 1;
  }

  auto oriented_normal = [&](std::uint32_t t) {
    const Triangle tri = canonical_rotation(mesh.triangles[t], g.positions);
    const Eigen::Vector3d n = (g.positions[tri[1]] - g.positions[tri[0]])
                                  .cross(g.positions[tri[2]] - g.positions[tri[0]]);
    return g.flipped[t] ? Eigen::Vector3d(-n) : n;
  };
  std::vector<DualEdge> records;
  for (const TriangleLink& link : links) {
    const Eigen::Vector3d n1 = oriented_normal(link.first), n2 = oriented_normal(link.second);
    const Eigen::Vector3d edge = g.positions[link.high] - g.positions[link.low];
    double beta = 0;
    std::uint32_t opposite = UINT32_MAX;
    for (std::uint32_t v : mesh.triangles[link.second])
      if (v != link.low && v != link.high) opposite = v;
    if (opposite != UINT32_MAX && n1.squaredNorm() > 0 && n2.squaredNorm() > 0) {
      beta = std::atan2(n1.cross(n2).norm(), n1.dot(n2));
      const Eigen::Vector3d midpoint = (g.positions[link.low] + g.positions[link.high]) / 2;
      if ((g.positions[opposite] - midpoint).dot(n1) > 0) beta = -beta;
    }
    EdgeStats stats;
    stats.add_edge(edge, beta);
    const std::uint32_t fa = mesh.face_of_triangle[link.first];
    const std::uint32_t fb = mesh.face_of_triangle[link.second];
    if (fa == fb)
      g.internal_edges.push_back({fa, stats});
    else
      records.push_back({std::min(fa, fb), std::max(fa, fb), stats});
  }
  std::stable_sort(records.begin(), records.end(), [](const DualEdge& a, const DualEdge& b) {
    return a.first != b.first ? a.first < b.first : a.second < b.second;
  });
  for (const DualEdge& r : records) {
    if (!g.edges.empty() && g.edges.back().first == r.first && g.edges.back().second == r.second)
      g.edges.back().shared += r.shared;
    else
      g.edges.push_back(r);
  }
  std::stable_sort(g.internal_edges.begin(), g.internal_edges.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });

  std::vector<std::uint32_t> parent(face_count);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const DualEdge& e : g.edges) {
    const std::uint32_t a = find(e.first), b = find(e.second);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  g.component_of_face.resize(face_count);
  std::vector<std::uint32_t> number(face_count, UINT32_MAX);
  for (std::uint32_t f = 0; f < face_count; ++f) {
    const std::uint32_t root = find(f);
    if (number[root] == UINT32_MAX) number[root] = g.component_count++;
    g.component_of_face[f] = number[root];
  }
  return g;
}

using testing::concatenated;
using testing::same_bits;

bool same_bits(const EdgeStats& a, const EdgeStats& b) {
  for (int i = 0; i < 6; ++i)
    if (!same_bits(a.tensor[i], b.tensor[i])) return false;
  return true;
}

template <int Rows, int Cols>
bool same_bits(const Eigen::Matrix<double, Rows, Cols>& a,
               const Eigen::Matrix<double, Rows, Cols>& b) {
  for (Eigen::Index i = 0; i < a.size(); ++i)
    if (!same_bits(a.data()[i], b.data()[i])) return false;
  return true;
}

// What the merge loop reads of a face, bit for bit: its statistics (moments about its origin,
// internal edges, normal sums, face planes, area) and its corners.
void expect_same_face(const DualGraph& got, std::uint32_t got_face, const DualGraph& want,
                      std::uint32_t want_face) {
  const ClusterStats a = got.face_stats(got_face), b = want.face_stats(want_face);
  ASSERT_TRUE(same_bits(a.moments.origin(), b.moments.origin()));
  for (std::size_t i = 0; i < a.moments.values().size(); ++i)
    ASSERT_TRUE(same_bits(a.moments.values()[i], b.moments.values()[i])) << "moment " << i;
  ASSERT_TRUE(same_bits(a.edges, b.edges));
  ASSERT_TRUE(same_bits(a.normal_sum, b.normal_sum));
  ASSERT_TRUE(same_bits(a.normal_position, b.normal_position));
  for (int i = 0; i < 6; ++i)
    ASSERT_TRUE(same_bits(a.face_planes.normal_normal[i], b.face_planes.normal_normal[i]));
  ASSERT_TRUE(same_bits(a.face_planes.normal_offset, b.face_planes.normal_offset));
  ASSERT_TRUE(same_bits(a.face_planes.offset_square, b.face_planes.offset_square));
  ASSERT_TRUE(same_bits(a.area, b.area));
  FaceCorners x, y;
  const bool by_corners = got.face_corners(got_face, x);
  ASSERT_EQ(by_corners, want.face_corners(want_face, y));
  if (!by_corners) return;
  ASSERT_EQ(x.triangle_count, y.triangle_count);
  ASSERT_TRUE(same_bits(x.centroid, y.centroid));
  for (std::uint32_t c = 0; c < x.corner_count(); ++c) {
    ASSERT_TRUE(same_bits(x.offsets[c], y.offsets[c])) << "corner " << c;
    ASSERT_TRUE(same_bits(x.weights[c], y.weights[c])) << "corner " << c;
  }
  ASSERT_TRUE(same_bits(x.second_moment, y.second_moment));
  ASSERT_TRUE(same_bits(x.normal_position, y.normal_position));
  ASSERT_TRUE(same_bits(x.edges, y.edges));
}

// DualGraph::in_spatial_order(): the same faces (statistics and corners bit for bit, the same
// orientation and components) and the same dual edges (each one's faces in their order, its
// mesh edges bit for bit), renumbered, with the edges sorted by their new faces.
void expect_same_graph_in_spatial_order(const DualGraph& graph) {
  const SpatialOrder order = graph.in_spatial_order();
  const DualGraph& renumbered = *order.graph;
  const std::uint32_t faces = graph.face_count();
  ASSERT_EQ(renumbered.face_count(), faces);
  ASSERT_EQ(renumbered.component_count(), graph.component_count());
  ASSERT_EQ(order.original_face.size(), faces);
  std::vector<std::uint32_t> new_face(faces, faces);
  for (std::uint32_t i = 0; i < faces; ++i) {
    const std::uint32_t f = order.original_face[i];
    ASSERT_LT(f, faces);
    ASSERT_EQ(new_face[f], faces) << "face " << f << " twice";
    new_face[f] = i;
    SCOPED_TRACE("new face " + std::to_string(i) + ", face " + std::to_string(f));
    ASSERT_EQ(renumbered.component_of_face()[i], graph.component_of_face()[f]);
    const std::uint32_t begin = graph.first_triangle(f),
                        count = graph.first_triangle(f + 1) - begin;
    ASSERT_EQ(renumbered.first_triangle(i + 1) - renumbered.first_triangle(i), count);
    for (std::uint32_t k = 0; k < count; ++k) {
      const std::uint32_t t = begin + k, u = renumbered.first_triangle(i) + k;
      ASSERT_EQ(renumbered.flipped(u), graph.flipped(t));
      const Triangle want = graph.corners(t), got = renumbered.corners(u);
      const std::array<double, 3> want_weights = graph.corner_weights(t),
                                  got_weights = renumbered.corner_weights(u);
      for (int c = 0; c < 3; ++c) {
        ASSERT_TRUE(same_bits(renumbered.position(got[c]), graph.position(want[c])));
        ASSERT_TRUE(same_bits(got_weights[c], want_weights[c]));
      }
    }
    expect_same_face(renumbered, i, graph, f);
  }
  const std::vector<DualEdge>& edges = renumbered.edges();
  ASSERT_EQ(edges.size(), graph.edges().size());
  ASSERT_EQ(order.original_edge.size(), edges.size());
  std::vector<bool> seen(edges.size());
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const std::uint32_t j = order.original_edge[k];
    ASSERT_LT(j, edges.size());
    ASSERT_FALSE(seen[j]) << "edge " << j << " twice";
    seen[j] = true;
    const DualEdge& want = graph.edges()[j];
    ASSERT_EQ(edges[k].first, new_face[want.first]) << "edge " << k;
    ASSERT_EQ(edges[k].second, new_face[want.second]) << "edge " << k;
    ASSERT_TRUE(same_bits(edges[k].shared, want.shared)) << "edge " << k;
    auto key = [](const DualEdge& e) {
      return std::make_pair(std::min(e.first, e.second), std::max(e.first, e.second));
    };
    if (k > 0) {
      ASSERT_LT(key(edges[k - 1]), key(edges[k])) << "edge " << k;
    }
  }
}

// Every output of DualGraph's constructor, built with `threads` threads, equals the reference's,
// bit for bit; and so does the graph in spatial order, renumbered.
void expect_reference_graph(const Mesh& mesh, const std::string& what, unsigned threads = 1) {
  SCOPED_TRACE(what + ", " + std::to_string(threads) + " threads");
  mesh.validate();
  const ReferenceGraph expected = reference_graph(mesh);
  // Uniform weights: corner_weights() shows the valences.
  const DualGraph graph(mesh, VertexWeights::Uniform, threads);

  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
    for (int a = 0; a < 3; ++a)
      ASSERT_TRUE(same_bits(graph.position(v)[a], expected.positions[v][a])) << "vertex " << v;
  for (std::uint32_t f = 0; f <= mesh.face_count(); ++f)
    ASSERT_EQ(graph.first_triangle(f), expected.first_triangle[f]) << "face " << f;
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    ASSERT_EQ(graph.flipped(t), expected.flipped[t] != 0) << "triangle " << t;
    const Triangle corners = canonical_rotation(mesh.triangles[t], expected.positions);
    ASSERT_EQ(graph.corners(t), corners) << "triangle " << t;
    const std::array<double, 3> weights = graph.corner_weights(t);
    for (int c = 0; c < 3; ++c)
      ASSERT_TRUE(same_bits(weights[c], 1.0 / expected.valence[corners[c]]))
          << "triangle " << t << " corner " << c;
  }

  const WorkingFrame frame = working_frame_for(mesh);
  EXPECT_EQ(graph.frame().exponent, frame.exponent);
  for (int a = 0; a < 3; ++a) ASSERT_TRUE(same_bits(graph.frame().center[a], frame.center[a]));
  ASSERT_EQ(graph.component_count(), expected.component_count);
  ASSERT_EQ(graph.component_of_face(), expected.component_of_face);

  ASSERT_EQ(graph.edges().size(), expected.edges.size());
  for (std::size_t e = 0; e < expected.edges.size(); ++e) {
    const DualEdge& got = graph.edges()[e];
    const DualEdge& want = expected.edges[e];
    ASSERT_EQ(got.first, want.first) << "edge " << e;
    ASSERT_EQ(got.second, want.second) << "edge " << e;
    ASSERT_TRUE(same_bits(got.shared, want.shared)) << "edge " << e;
  }

  // The internal edges, as face_stats() adds them: in order, from zero.
  std::vector<EdgeStats> internal(mesh.face_count());
  for (const auto& [face, stats] : expected.internal_edges) internal[face] += stats;
  ClusterStats stats;
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
    if (graph.first_triangle(f + 1) - graph.first_triangle(f) < 2) continue;
    graph.face_stats(f, stats, false, 2);
    ASSERT_TRUE(same_bits(stats.edges, internal[f])) << "face " << f;
  }
  expect_same_graph_in_spatial_order(graph);
}

// The same surface with its vertices, faces and each face's first corner in random order.
Mesh shuffled(const Mesh& mesh, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::uint32_t> vertex_order(mesh.vertex_count()), face_order(mesh.face_count());
  std::iota(vertex_order.begin(), vertex_order.end(), 0u);
  std::iota(face_order.begin(), face_order.end(), 0u);
  std::shuffle(vertex_order.begin(), vertex_order.end(), rng);
  std::shuffle(face_order.begin(), face_order.end(), rng);
  std::vector<Vec3> positions(mesh.vertex_count());
  std::vector<std::uint32_t> new_index(mesh.vertex_count());
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    positions[v] = mesh.positions[vertex_order[v]];
    new_index[vertex_order[v]] = v;
  }
  std::vector<std::uint32_t> offsets{0}, vertices;
  for (std::uint32_t f : face_order) {
    const std::span<const std::uint32_t> polygon = mesh.polygon(f);
    const std::size_t start = rng() % polygon.size();
    for (std::size_t i = 0; i < polygon.size(); ++i)
      vertices.push_back(new_index[polygon[(start + i) % polygon.size()]]);
    offsets.push_back(static_cast<std::uint32_t>(vertices.size()));
  }
  return Mesh::from_polygons(std::move(positions), std::move(offsets), std::move(vertices));
}

// The mesh with every triangle turned over (a closed surface then faces inward).
Mesh reversed(Mesh mesh) {
  for (Triangle& t : mesh.triangles) std::swap(t[1], t[2]);
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f)
    std::reverse(mesh.polygon_vertices.begin() + mesh.polygon_offsets[f],
                 mesh.polygon_vertices.begin() + mesh.polygon_offsets[f + 1]);
  return mesh;
}

// A band of `segments` quads around a circle, its two ends joined after half a twist (a Möbius
// band, not orientable) or none.
Mesh band(int segments, bool twisted) {
  std::vector<Vec3> positions;
  for (int i = 0; i < segments; ++i) {
    const double angle = 2 * std::numbers::pi * i / segments;
    const double twist = twisted ? angle / 2 : 0;
    for (double s : {-0.3, 0.3})
      positions.push_back({(1 + s * std::cos(twist)) * std::cos(angle),
                           (1 + s * std::cos(twist)) * std::sin(angle), s * std::sin(twist)});
  }
  std::vector<Triangle> triangles;
  const auto n = static_cast<std::uint32_t>(segments);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t a = 2 * i, b = 2 * i + 1;
    std::uint32_t c = 2 * ((i + 1) % n), d = c + 1;
    if (twisted && i + 1 == n) std::swap(c, d);
    triangles.push_back({a, c, b});
    triangles.push_back({b, c, d});
  }
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

// Random triangles on a few random (sometimes coincident or collinear) points: most edges are
// non-manifold, many triangles degenerate or repeated, orientations arbitrary. Consecutive
// triangles are grouped into faces of 1 to `max_face_size` triangles (whatever their shape: the
// graph does not look at the polygons).
Mesh random_soup(std::uint64_t seed, std::uint32_t vertex_count, std::uint32_t triangle_count,
                 std::uint32_t max_face_size) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> coordinate(-1, 1);
  Mesh mesh;
  for (std::uint32_t v = 0; v < vertex_count; ++v) {
    const std::uint64_t kind = rng() % 8;
    if (kind == 0 && v > 0) {
      mesh.positions.push_back(mesh.positions[rng() % v]);  // coincident
    } else if (kind == 1 && v > 1) {
      const Vec3 a = mesh.positions[rng() % v], b = mesh.positions[rng() % v];
      mesh.positions.push_back({(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
    } else {
      mesh.positions.push_back({coordinate(rng), coordinate(rng), coordinate(rng)});
    }
  }
  std::uint32_t face = 0, left_in_face = 0;
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    Triangle tri;
    for (std::uint32_t& v : tri) v = static_cast<std::uint32_t>(rng() % vertex_count);
    if (t > 0 && rng() % 6 == 0) {  // the same edges again, in either direction
      tri = mesh.triangles[rng() % t];
      if (rng() % 2) std::swap(tri[0], tri[1]);
    }
    if (left_in_face == 0) {
      if (t > 0) ++face;
      left_in_face = 1 + static_cast<std::uint32_t>(rng() % max_face_size);
      mesh.polygon_vertices.insert(mesh.polygon_vertices.end(), tri.begin(), tri.end());
      mesh.polygon_offsets.push_back(static_cast<std::uint32_t>(mesh.polygon_vertices.size()));
    }
    --left_in_face;
    mesh.triangles.push_back(tri);
    mesh.face_of_triangle.push_back(face);
  }
  return mesh;
}

TEST(DualGraph, EqualsTheReferenceOnGeneratedShapes) {
  for (const std::string& name : shape_names())
    for (Tessellation tessellation : {Tessellation::Uniform, Tessellation::Cad}) {
      ShapeOptions options;
      options.tessellation = tessellation;
      options.edge_length = 0.04;
      const Mesh exact = make_shape(name, options).mesh;
      options.noise = 0.003;
      options.random_motion = true;
      options.seed = 7;
      const Mesh noisy = make_shape(name, options).mesh;
      const std::string what = name + (tessellation == Tessellation::Cad ? " cad" : " uniform");
      expect_reference_graph(exact, what);
      expect_reference_graph(noisy, what + " noisy");
      expect_reference_graph(shuffled(noisy, 3), what + " noisy shuffled");
      expect_reference_graph(reversed(exact), what + " inward");
    }
}

TEST(DualGraph, EqualsTheReferenceOnCgalMeshes) {
  for (const char* name : {"fandisk.off", "bunny00.off"}) {
    const Mesh mesh = read_mesh(testing::cgal_mesh(name));
    expect_reference_graph(mesh, name);
    expect_reference_graph(shuffled(mesh, 11), std::string(name) + " shuffled");
  }
}

TEST(DualGraph, EqualsTheReferenceForAnyNumberOfThreads) {
  // Large enough for the faces to be split between threads, with polygons and non-manifold
  // edges on the way.
  const Mesh bunny = read_mesh(testing::cgal_mesh("bunny00.off"));
  const Mesh soup = random_soup(17, 4000, 90000, 3);
  std::vector<Vec3> positions;
  std::vector<std::uint32_t> offsets{0}, vertices;
  const std::uint32_t n = 180;
  for (std::uint32_t i = 0; i <= n; ++i)
    for (std::uint32_t j = 0; j <= n; ++j)
      positions.push_back({double(i), double(j), std::sin(0.1 * i) * std::cos(0.13 * j)});
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = 0; j < n; ++j) {
      const std::uint32_t v = i * (n + 1) + j;
      if ((i + j) % 3 == 0) {  // a quad as two triangle faces
        vertices.insert(vertices.end(), {v, v + n + 1, v + n + 2, v, v + n + 2, v + 1});
        offsets.insert(offsets.end(), {offsets.back() + 3, offsets.back() + 6});
      } else {
        vertices.insert(vertices.end(), {v, v + n + 1, v + n + 2, v + 1});
        offsets.push_back(offsets.back() + 4);
      }
    }
  const Mesh quads = Mesh::from_polygons(positions, offsets, vertices);
  for (unsigned threads : {1u, 2u, 3u, 5u}) {
    expect_reference_graph(bunny, "bunny00", threads);
    expect_reference_graph(soup, "soup", threads);
    expect_reference_graph(quads, "quads", threads);
  }
}

TEST(DualGraph, EqualsTheReferenceWhenBothSignedZerosBoundTheBox) {
  // In the plane x = 0, the x of the corners alternately +0 and -0: the first corner (-0) bounds
  // the box, whose centre is then -0, not the first vertex (+0). An unused vertex lies outside.
  const Mesh mesh = Mesh::from_triangles(
      {{0.0, 0, 0}, {-0.0, 1, 0}, {0.0, 0, 1}, {-0.0, 1, 1}, {-5, -5, -5}}, {{1, 2, 0}, {1, 3, 2}});
  expect_reference_graph(mesh, "signed zeros");
  EXPECT_TRUE(std::signbit(DualGraph(mesh, VertexWeights::Area).frame().center.x()));
}

TEST(DualGraph, EqualsTheReferenceOnPolygonFaces) {
  // A grid of quads with an L-shaped face (sharing two mesh edges with the quad in its corner)
  // and a large square face: internal edges, and several links between one pair of faces.
  std::vector<Vec3> positions;
  const int n = 12;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      positions.push_back({double(i), double(j), 0.05 * std::sin(i * 0.7) * std::cos(j * 1.3)});
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  std::vector<std::uint32_t> offsets{0}, vertices;
  auto add_face = [&](std::initializer_list<std::pair<int, int>> corners) {
    for (auto [i, j] : corners) vertices.push_back(id(i, j));
    offsets.push_back(static_cast<std::uint32_t>(vertices.size()));
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const bool in_l = i + j < 2, in_square = i >= 4 && i < 8 && j >= 4 && j < 8;
      if (!in_l && !in_square) add_face({{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}});
    }
  add_face({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 1}});
  add_face({{4, 4},
            {5, 4},
            {6, 4},
            {7, 4},
            {8, 4},
            {8, 5},
            {8, 6},
            {8, 7},
            {8, 8},
            {7, 8},
            {6, 8},
            {5, 8},
            {4, 8},
            {4, 7},
            {4, 6},
            {4, 5}});
  const Mesh grid = Mesh::from_polygons(positions, offsets, vertices);
  expect_reference_graph(grid, "grid");
  expect_reference_graph(shuffled(grid, 5), "grid shuffled");

  // A closed polygon mesh: a cube of quads, inward and outward, and with a face twice.
  const Mesh cube = Mesh::from_polygons(
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
      {0, 4, 8, 12, 16, 20, 24},
      {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7});
  expect_reference_graph(cube, "cube");
  expect_reference_graph(reversed(cube), "cube inward");
  expect_reference_graph(concatenated({cube, reversed(cube), grid}), "cubes and grid");
  std::vector<std::uint32_t> twice(cube.polygon_vertices);
  twice.insert(twice.end(), {0, 3, 2, 1});
  expect_reference_graph(Mesh::from_polygons(cube.positions, {0, 4, 8, 12, 16, 20, 24, 28}, twice),
                         "cube with a face twice");
}

TEST(DualGraph, EqualsTheReferenceOnNonManifoldEdges) {
  // Pages of a book: k triangles on one edge, alternately oriented, then the same with a closed
  // tetrahedron sharing the spine.
  for (std::uint32_t pages = 3; pages <= 6; ++pages) {
    std::vector<Vec3> positions{{0, 0, 0}, {0, 0, 1}};
    std::vector<Triangle> triangles;
    for (std::uint32_t p = 0; p < pages; ++p) {
      const double angle = 2 * std::numbers::pi * p / pages;
      positions.push_back({std::cos(angle), std::sin(angle), 0.5});
      const std::uint32_t v = p + 2;
      triangles.push_back(p % 2 ? Triangle{0, 1, v} : Triangle{1, 0, v});
    }
    const Mesh book = Mesh::from_triangles(positions, triangles);
    expect_reference_graph(book, "book of " + std::to_string(pages));
    positions.push_back({0.2, 0.3, -1});
    const auto apex = static_cast<std::uint32_t>(positions.size() - 1);
    triangles.insert(triangles.end(), {{0, 2, apex}, {2, 1, apex}, {1, 0, apex}});
    expect_reference_graph(shuffled(Mesh::from_triangles(positions, triangles), pages),
                           "book and tetrahedron " + std::to_string(pages));
  }
  // Closed surfaces on shared vertices: two tetrahedra sharing an edge, a box and the same box
  // again (every edge on four triangles), and a box and its inward copy.
  const std::vector<Vec3> points{{0, 0, 0}, {1, 0, 0},    {0, 1, 0},
                                 {0, 0, 1}, {-1, 0, 0.2}, {0, -1, 1}};
  expect_reference_graph(
      Mesh::from_triangles(
          points,
          {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 1, 4}, {1, 0, 5}, {0, 4, 5}, {4, 1, 5}}),
      "tetrahedra on an edge");
  const Mesh box = make_shape("box", ShapeOptions{}).mesh;
  std::vector<Triangle> doubled = box.triangles;
  doubled.insert(doubled.end(), box.triangles.begin(), box.triangles.end());
  expect_reference_graph(Mesh::from_triangles(box.positions, doubled), "box twice");
  doubled.resize(box.triangles.size());
  for (Triangle t : box.triangles) doubled.push_back({t[0], t[2], t[1]});
  expect_reference_graph(shuffled(Mesh::from_triangles(box.positions, doubled), 9),
                         "box and inward box");
}

TEST(DualGraph, EqualsTheReferenceOnSeveralComponents) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.1;
  const Mesh sphere = make_shape("sphere", options).mesh;
  const Mesh single = Mesh::from_triangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
  const Mesh open_sheet = testing::grid_mesh(6, 9, [](double u, double v) {
    return Vec3{u, v, 0.2 * u * v};
  });
  const Mesh mesh = concatenated({single, reversed(sphere), open_sheet, band(30, true),
                                  band(24, false), sphere, reversed(open_sheet), single});
  expect_reference_graph(mesh, "components");
  expect_reference_graph(shuffled(mesh, 2), "components shuffled");
  expect_reference_graph(band(41, true), "Möbius band");
  expect_reference_graph(shuffled(band(41, true), 4), "Möbius band shuffled");
}

TEST(DualGraph, EqualsTheReferenceOnDegenerateAndDuplicateTriangles) {
  // Zero-area triangles (collinear corners, a repeated corner, one vertex thrice) in a closed
  // surface and alone, and every triangle of a surface twice.
  std::vector<Vec3> positions{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5, 0, 0}};
  const std::vector<Triangle> tetrahedron{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  std::vector<Triangle> triangles = tetrahedron;
  triangles.insert(triangles.end(), {{0, 4, 1}, {0, 1, 0}, {1, 0, 0}, {2, 2, 2}, {4, 1, 3}});
  expect_reference_graph(Mesh::from_triangles(positions, triangles), "degenerate");
  triangles = tetrahedron;
  triangles.insert(triangles.end(), tetrahedron.begin(), tetrahedron.end());
  triangles.insert(triangles.end(), {{0, 1, 2}, {3, 3, 1}});
  expect_reference_graph(Mesh::from_triangles(positions, triangles), "duplicates");
  expect_reference_graph(Mesh::from_triangles(positions, {{0, 0, 0}}), "a point");
}

TEST(DualGraph, EqualsTheReferenceOnRandomSoups) {
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    const auto vertices = static_cast<std::uint32_t>(3 + seed % 40);
    const auto triangles = static_cast<std::uint32_t>(1 + (seed * 7919) % 150);
    expect_reference_graph(random_soup(seed, vertices, triangles, 1 + seed % 4),
                           "soup " + std::to_string(seed));
  }
}

}  // namespace
}  // namespace primseg
