// The hierarchy is the greedy order, nothing else: a naive implementation that scans every pair of
// adjacent clusters at every step and merges the cheapest gives the same tree, bit for bit, on
// small noisy meshes and on clean ones, whose flat and exactly curved regions tie at cost zero
// in large numbers (settled by the merged degree, then node ids). This guards the queue, the
// bookkeeping of adjacency and shared edges, the caches and the parallel evaluation together, and
// the reading of faces and pairs by their corners or their statistics (polygon faces, tori).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <set>

#include "model_selection.hpp"
#include "primseg/cluster_view.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/shape_generator.hpp"

namespace primseg {
namespace {

// Merges in the greedy order, (cost, type, merged degree at evaluation for a zero cost, smaller
// node id, larger node id), scanning every live candidate at every step; exact ties above zero go
// to the lower current degree, then node ids. A candidate is re-evaluated when one of its
// clusters changes. The
// unions' statistics and the mesh edges between clusters are formed as the builder forms them
// (the parts in the order of the edge's ends, the edge kept where two meet first).
std::vector<Merge> naive_greedy(const Mesh& mesh, const HierarchyOptions& options) {
  const DualGraph graph(mesh, options.weights);
  const detail::ModelSelector selector(options);
  std::vector<ClusterStats> stats;
  // A cluster that is still one face or a pair is read by its corners, as the builder reads it.
  std::vector<std::optional<FaceCorners>> corners(graph.face_count());
  std::vector<std::uint32_t> node;
  for (std::uint32_t f = 0; f < graph.face_count(); ++f) {
    stats.push_back(graph.face_stats(f, selector.needs_samples()));
    if (FaceCorners c; !selector.needs_samples() && graph.face_corners(f, c)) corners[f] = c;
    node.push_back(f);
  }
  auto part = [&](std::uint32_t cluster) -> ClusterPart {
    if (corners[cluster]) return *corners[cluster];
    return stats[cluster];
  };
  struct Edge {
    std::uint32_t a, b;  // clusters (by their first face), in the builder's order
    EdgeStats shared;
    bool alive = true;
    bool evaluated = false;
    detail::SelectedModel model;
    std::uint32_t degree = 0;  // merged degree when evaluated, for a zero cost
  };
  std::vector<Edge> edges;
  for (const DualEdge& e : graph.edges())
    edges.push_back({e.first, e.second, e.shared, true, false, {}, 0});
  std::vector<Merge> merges;
  for (std::uint32_t next = graph.face_count();; ++next) {
    auto merged_degree = [&](const Edge& of) {
      std::set<std::uint32_t> neighbours;
      for (const Edge& e : edges)
        if (e.alive)
          for (auto [end, other] : {std::pair(e.a, e.b), std::pair(e.b, e.a)})
            if ((end == of.a || end == of.b) && other != of.a && other != of.b)
              neighbours.insert(other);
      return static_cast<std::uint32_t>(neighbours.size());
    };
    auto pair = [&](const Edge& e) {
      return std::pair(std::min(node[e.a], node[e.b]), std::max(node[e.a], node[e.b]));
    };
    auto key = [&](const Edge& e) {
      return std::tuple(e.model.cost, e.model.fit.primitive.type, e.degree, pair(e));
    };
    for (Edge& e : edges)
      if (e.alive && !e.evaluated) {
        e.model = selector.select(ClusterView(part(e.a), part(e.b), e.shared));
        e.degree = e.model.cost == 0 ? merged_degree(e) : 0;
        e.evaluated = true;
      }
    Edge* best = nullptr;
    for (Edge& e : edges)
      if (e.alive && (!best || key(e) < key(*best))) best = &e;
    if (!best) break;
    if (best->model.cost > 0) {
      const std::uint32_t cost_type_degree = merged_degree(*best);
      std::uint32_t best_degree = cost_type_degree;
      for (Edge& e : edges)
        if (e.alive && &e != best && e.model.cost == best->model.cost &&
            e.model.fit.primitive.type == best->model.fit.primitive.type) {
          const std::uint32_t degree = merged_degree(e);
          if (degree < best_degree || (degree == best_degree && pair(e) < pair(*best))) {
            best = &e;
            best_degree = degree;
          }
        }
    }
    const std::uint32_t a = best->a, b = best->b;
    Merge record;
    record.first = std::min(node[a], node[b]);
    record.second = std::max(node[a], node[b]);
    record.cost = best->model.cost;
    record.error = best->model.fit.error;
    record.primitive = graph.frame().to_input(best->model.fit.primitive);
    merges.push_back(record);
    // A pair of faces (two leaves) is read by its corners too, while they are few.
    const bool leaves = node[a] < graph.face_count() && node[b] < graph.face_count();
    FaceCorners united;
    if (leaves && corners[a] && corners[b] &&
        FaceCorners::unite(*corners[a], *corners[b], best->shared, united)) {
      corners[a] = united;
    } else {
      stats[a] = ClusterView(part(a), part(b), best->shared).stats();
      corners[a].reset();
    }
    node[a] = next;
    best->alive = false;
    // a's edges first, then b's: an edge of b to a neighbour a already has is summed into a's.
    std::map<std::uint32_t, Edge*> kept;  // neighbour -> its edge to a
    for (Edge& e : edges)
      if (e.alive && (e.a == a || e.b == a)) {
        kept[e.a == a ? e.b : e.a] = &e;
        e.evaluated = false;
      }
    for (Edge& e : edges)
      if (e.alive && (e.a == b || e.b == b)) {
        const std::uint32_t other = e.a == b ? e.b : e.a;
        if (auto it = kept.find(other); it != kept.end()) {
          it->second->shared += e.shared;
          e.alive = false;
        } else {
          (e.a == b ? e.a : e.b) = a;
          e.evaluated = false;
        }
      }
  }
  return merges;
}

void expect_naive_greedy(
    const Mesh& mesh, const std::string& what,
    const std::vector<PrimitiveType>& primitives = HierarchyOptions{}.primitives) {
  for (unsigned threads : {1u, 2u}) {
    HierarchyOptions options;
    options.threads = threads;
    options.primitives = primitives;
    const Hierarchy tree = build_hierarchy(mesh, options);
    const std::vector<Merge> naive = naive_greedy(mesh, options);
    ASSERT_EQ(naive.size() + tree.component_count() - 1, tree.merges().size()) << what;
    for (std::size_t k = 0; k < naive.size(); ++k) {
      const Merge& m = tree.merges()[k];
      ASSERT_EQ(m.first, naive[k].first) << what << " merge " << k;
      ASSERT_EQ(m.second, naive[k].second) << what << " merge " << k;
      ASSERT_EQ(m.cost, naive[k].cost) << what << " merge " << k;
      ASSERT_EQ(m.error, naive[k].error) << what << " merge " << k;
      ASSERT_EQ(m.primitive.type, naive[k].primitive.type) << what << " merge " << k;
      ASSERT_EQ(m.primitive.radius, naive[k].primitive.radius) << what << " merge " << k;
    }
  }
}

TEST(GreedyReference, NoisyMeshesMergeInTheNaiveGreedyOrder) {
  std::uint64_t seed = 5;
  for (const char* name : {"box_with_hole", "cylinder_with_sphere_cap", "box_with_dome"}) {
    ShapeOptions options;
    options.tessellation = Tessellation::Uniform;
    options.edge_length = 0.06;
    options.noise = 0.003;
    options.random_motion = true;
    options.seed = seed++;
    const Mesh mesh = make_shape(name, options).mesh;
    ASSERT_GT(mesh.face_count(), 500u) << name;
    expect_naive_greedy(mesh, name);
    // Planes alone: the builder then keeps its clusters' moments up to degree 2 only, the naive
    // order all of them.
    expect_naive_greedy(mesh, std::string(name) + ", planes", {PrimitiveType::Plane});
  }
}

TEST(GreedyReference, CleanMeshesSettleTheirZeroCostTiesAsTheNaiveGreedyOrder) {
  std::uint64_t seed = 9;
  for (const char* name : {"box", "sphere", "box_with_hole", "filleted_cylinder"})
    for (Tessellation tessellation : {Tessellation::Cad, Tessellation::Uniform}) {
      ShapeOptions options;
      options.tessellation = tessellation;
      options.edge_length = 0.06;
      options.random_motion = true;
      options.seed = seed++;
      const Mesh mesh = make_shape(name, options).mesh;
      expect_naive_greedy(
          mesh, std::string(name) + (tessellation == Tessellation::Cad ? " cad" : " uniform"));
    }
}

// Polygon faces: quads (two triangles, read by their corners, and pairs of them too), hexagons
// (four triangles: a face by its corners, its pairs by their statistics) and octagons (six: by
// their statistics), on a noisy curved sheet; with planes and spheres only (lazy bounds); and with
// the torus enabled, which reads every cluster by its statistics (samples).
TEST(GreedyReference, PolygonMeshesMergeInTheNaiveGreedyOrder) {
  const int n = 14;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0, 0.01);
  std::vector<Vec3> positions;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      positions.push_back(
          {0.1 * i, 0.1 * j, 0.3 * std::sin(0.25 * i) * std::cos(0.2 * j) + noise(rng)});
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  std::vector<std::uint32_t> offsets{0}, vertices;
  std::vector<bool> used(n * n, false);
  auto add_face = [&](std::initializer_list<std::pair<int, int>> corners,
                      std::initializer_list<std::pair<int, int>> cells) {
    for (auto [i, j] : corners) vertices.push_back(id(i, j));
    offsets.push_back(static_cast<std::uint32_t>(vertices.size()));
    for (auto [i, j] : cells) used[i * n + j] = true;
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (used[i * n + j]) continue;
      const bool fits_2x2 = i + 1 < n && j + 1 < n && !used[(i + 1) * n + j] &&
                            !used[i * n + j + 1] && !used[(i + 1) * n + j + 1];
      if (i % 6 == 0 && j % 6 == 0 && fits_2x2)
        add_face({{i, j},
                  {i + 1, j},
                  {i + 2, j},
                  {i + 2, j + 1},
                  {i + 2, j + 2},
                  {i + 1, j + 2},
                  {i, j + 2},
                  {i, j + 1}},
                 {{i, j}, {i + 1, j}, {i, j + 1}, {i + 1, j + 1}});
      else if (i % 4 == 1 && j % 5 == 2 && i + 1 < n && !used[(i + 1) * n + j])
        add_face({{i, j}, {i + 1, j}, {i + 2, j}, {i + 2, j + 1}, {i + 1, j + 1}, {i, j + 1}},
                 {{i, j}, {i + 1, j}});
      else
        add_face({{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}}, {{i, j}});
    }
  const Mesh mesh = Mesh::from_polygons(positions, offsets, vertices);
  std::size_t hexagons = 0, octagons = 0;
  for (std::size_t f = 0; f + 1 < offsets.size(); ++f) {
    hexagons += offsets[f + 1] - offsets[f] == 6;
    octagons += offsets[f + 1] - offsets[f] == 8;
  }
  ASSERT_GT(hexagons, 3u);
  ASSERT_GT(octagons, 3u);
  expect_naive_greedy(mesh, "polygon sheet");
  // Planes and spheres: candidates wait under bounds, checked with each neighbour's spread from
  // its corners (the octagons' from their statistics).
  expect_naive_greedy(mesh, "polygon sheet with planes and spheres",
                      {PrimitiveType::Plane, PrimitiveType::Sphere});
  expect_naive_greedy(
      mesh, "polygon sheet with tori",
      {PrimitiveType::Plane, PrimitiveType::Cylinder, PrimitiveType::Sphere, PrimitiveType::Torus});
}

}  // namespace
}  // namespace primseg
