// A view of the union of two clusters gives what a direct computation over the union's points
// gives, without forming the union's moments; a view of one cluster gives that cluster's.
#include "primseg/cluster_view.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <numeric>
#include <random>

#include "primitives/pratt_fit.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/shape_generator.hpp"
#include "support/test_support.hpp"
#include "symmetric_eigen3.hpp"

namespace primseg {
namespace {

// Weighted corners of a set of faces, and direct sums over them.
struct Corners {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> weights;

  Corners(const DualGraph& graph, const std::vector<std::uint32_t>& faces) {
    for (std::uint32_t f : faces)
      for (std::uint32_t t = graph.first_triangle(f); t < graph.first_triangle(f + 1); ++t) {
        const auto w = graph.corner_weights(t);
        for (int c = 0; c < 3; ++c) {
          points.push_back(graph.position(graph.corners(t)[c]));
          weights.push_back(w[c]);
        }
      }
  }
  Eigen::Vector3d centroid() const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double w = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      sum += weights[i] * points[i];
      w += weights[i];
    }
    return sum / w;
  }
  // Σ w f(y), y about the centroid.
  template <typename F>
  auto sum(F f) const {
    const Eigen::Vector3d c = centroid();
    decltype(f(Eigen::Vector3d())) total = f(Eigen::Vector3d::Zero()) * 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) total += weights[i] * f(points[i] - c);
    return total;
  }
};

ClusterStats stats_of(const DualGraph& graph, const std::vector<std::uint32_t>& faces) {
  ClusterStats stats = graph.face_stats(faces.front());
  for (std::size_t i = 1; i < faces.size(); ++i) stats.merge(graph.face_stats(faces[i]), {});
  return stats.centred();
}

void expect_near(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double tolerance,
                 const char* what) {
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), tolerance) << what << "\n" << a << "\nvs\n" << b;
}

// Every quantity of `view`, the union of the faces a and b and the mesh edges `shared` between
// them (plus `inner` inside the parts beyond their faces' own edges), against direct sums over the
// union's corners; its whole statistics against the old way of forming them (merge, then centre).
void expect_union_of(const ClusterView& view, const DualGraph& graph,
                     const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b,
                     const EdgeStats& shared, const EdgeStats& inner, int trial) {
  std::vector<std::uint32_t> both = a;
  both.insert(both.end(), b.begin(), b.end());
  const ClusterStats stats_a = stats_of(graph, a), stats_b = stats_of(graph, b);
  const Corners corners(graph, both);
  const double scale = corners.sum([](const Eigen::Vector3d& y) { return y.squaredNorm(); });

  EXPECT_NEAR(view.weight(), corners.sum([](const Eigen::Vector3d&) { return 1.0; }),
              1e-12 * view.weight());
  expect_near(view.centroid(), corners.centroid(), 1e-13, "centroid");
  expect_near(view.second_moment(), corners.sum([](const Eigen::Vector3d& y) -> Eigen::Matrix3d {
    return y * y.transpose();
  }),
              1e-12 * scale, "second moment");
  const ClusterView::RadialMoments& radial = view.radial_moments();
  const double radius = std::sqrt(scale / view.weight());
  expect_near(radial.third, corners.sum([](const Eigen::Vector3d& y) -> Eigen::Vector3d {
    return y * y.squaredNorm();
  }),
              1e-12 * scale * radius, "radial third");
  EXPECT_NEAR(radial.fourth, corners.sum([](const Eigen::Vector3d& y) {
    return y.squaredNorm() * y.squaredNorm();
  }),
              1e-12 * scale * radius * radius);
  for (int axes = 0; axes < 4; ++axes) {
    const Eigen::Vector3d axis =
        Eigen::Vector3d(std::cos(axes + trial), std::sin(2.0 * axes), 0.3 * axes - 0.5)
            .normalized();
    const ClusterView::AxialMoments axial = view.axial_moments(axis);
    expect_near(axial.third, corners.sum([&](const Eigen::Vector3d& y) -> Eigen::Vector3d {
      return y * std::pow(axis.dot(y), 2);
    }),
                1e-12 * scale * radius, "axial third");
    EXPECT_NEAR(axial.mixed, corners.sum([&](const Eigen::Vector3d& y) {
      return y.squaredNorm() * std::pow(axis.dot(y), 2);
    }),
                1e-12 * scale * radius * radius);
    EXPECT_NEAR(axial.fourth,
                corners.sum([&](const Eigen::Vector3d& y) { return std::pow(axis.dot(y), 4); }),
                1e-12 * scale * radius * radius);
  }
  EXPECT_EQ(view.triangle_count(), stats_a.triangle_count + stats_b.triangle_count);
  EXPECT_NEAR(view.area(), stats_a.area + stats_b.area, 1e-15 * view.area());
  const Eigen::Matrix3d tensor = stats_a.edges.tensor_matrix() + stats_b.edges.tensor_matrix() +
                                 shared.tensor_matrix() + inner.tensor_matrix();
  expect_near(view.edge_tensor(), tensor, 1e-14, "edge tensor");

  // The view's whole statistics equal the old way of forming them (merge, then centre), and
  // the single view of them gives the same quantities.
  ClusterStats merged = stats_a;
  merged.merge(stats_b, shared);
  merged.edges += inner;
  merged = merged.centred();
  const ClusterStats& formed = view.stats();
  for (int n = 0; n < Moments::kCount; ++n)
    EXPECT_NEAR(formed.moments.values()[n], merged.moments.values()[n],
                1e-12 * scale * (1 + radius * radius))
        << n;
  expect_near(formed.normal_position, merged.normal_position, 1e-13 * view.area(),
              "normal position");
  expect_near(formed.face_planes.normal_normal_matrix(), merged.face_planes.normal_normal_matrix(),
              1e-13 * view.area(), "face planes");
  EXPECT_NEAR(formed.face_planes.offset_square, merged.face_planes.offset_square,
              1e-12 * view.area());
  expect_near(formed.edges.tensor_matrix(), tensor, 1e-14, "formed edge tensor");
  const ClusterView single(formed);
  expect_near(single.second_moment(), view.second_moment(), 1e-13 * scale, "single view");
  const Eigen::Matrix3d q =
      Eigen::Matrix3d::Identity() - Eigen::Vector3d::UnitZ() * Eigen::Vector3d::UnitZ().transpose();
  const Eigen::Vector3d point = view.centroid() + Eigen::Vector3d(0.3, -0.2, 0.1);
  EXPECT_NEAR(view.normal_alignment(q, point, 0.7), merged.normal_alignment(q, point, 0.7), 1e-12);
  EXPECT_NEAR(single.normal_alignment(q, point, 0.7), merged.normal_alignment(q, point, 0.7),
              1e-12);
  // With degree 2 only, the moments up to degree 2 are the same bits and the rest zero.
  const ClusterStats low = view.stats(2);
  for (int n = 0; n < Moments::kCount; ++n)
    EXPECT_EQ(low.moments.values()[n],
              n < Moments::kCountUpToDegree2 ? formed.moments.values()[n] : 0.0)
        << n;
}

// The faces of the graph in a random order.
std::vector<std::uint32_t> shuffled_faces(const DualGraph& graph, std::mt19937_64& rng) {
  std::vector<std::uint32_t> all(graph.face_count());
  std::iota(all.begin(), all.end(), 0u);
  std::shuffle(all.begin(), all.end(), rng);
  return all;
}

TEST(ClusterView, UnionQuantitiesEqualDirectSumsOverTheUnionsPoints) {
  const Mesh mesh = testing::noisy_uniform_shape("cylinder_with_sphere_cap");
  for (VertexWeights weights : {VertexWeights::Area, VertexWeights::Uniform}) {
    const DualGraph graph(mesh, weights);
    std::mt19937_64 rng(3);
    // Two disjoint random sets of faces (adjacency does not matter for the moments).
    for (int trial = 0; trial < 20; ++trial) {
      const std::vector<std::uint32_t> all = shuffled_faces(graph, rng);
      const std::size_t na = 1 + trial * 37, nb = 1 + trial * 11;
      const std::vector<std::uint32_t> a(all.begin(), all.begin() + na);
      const std::vector<std::uint32_t> b(all.begin() + na, all.begin() + na + nb);
      const ClusterStats stats_a = stats_of(graph, a), stats_b = stats_of(graph, b);
      EdgeStats shared;
      shared.add_edge(Eigen::Vector3d(0.1, 0.2, 0.3), 0.4);
      expect_union_of(ClusterView(stats_a, stats_b, shared), graph, a, b, shared, {}, trial);
    }
  }
}

// The merge loop reads single faces and pairs of faces by their corners: a view with such parts
// gives the same quantities as with their statistics, in either order and against either kind.
TEST(ClusterView, FacesAndPairsByTheirCornersGiveTheUnionsQuantities) {
  const Mesh mesh = testing::noisy_uniform_shape("box_with_dome");
  for (VertexWeights weights : {VertexWeights::Area, VertexWeights::Uniform}) {
    const DualGraph graph(mesh, weights);
    std::mt19937_64 rng(7);
    for (int trial = 0; trial < 20; ++trial) {
      const std::vector<std::uint32_t> all = shuffled_faces(graph, rng);
      const std::uint32_t f = all[0], g = all[1], h = all[2];
      const std::vector<std::uint32_t> cluster(all.begin() + 3, all.begin() + 3 + 5 * trial + 1);
      const ClusterStats stats = stats_of(graph, cluster);
      FaceCorners face_f, face_g, face_h, pair;
      ASSERT_TRUE(graph.face_corners(f, face_f));
      ASSERT_TRUE(graph.face_corners(g, face_g));
      ASSERT_TRUE(graph.face_corners(h, face_h));
      EdgeStats shared, inner;
      shared.add_edge(Eigen::Vector3d(0.1, 0.2, 0.3), 0.4);
      inner.add_edge(Eigen::Vector3d(-0.2, 0.1, 0.05), -0.3);
      ASSERT_TRUE(FaceCorners::unite(face_f, face_g, inner, pair));
      EXPECT_EQ(pair.triangle_count, 2u);

      expect_union_of(ClusterView(stats, face_h, shared), graph, cluster, {h}, shared, {}, trial);
      expect_union_of(ClusterView(face_h, stats, shared), graph, {h}, cluster, shared, {}, trial);
      expect_union_of(ClusterView(face_f, face_h, shared), graph, {f}, {h}, shared, {}, trial);
      expect_union_of(ClusterView(pair, stats, shared), graph, {f, g}, cluster, shared, inner,
                      trial);
      expect_union_of(ClusterView(stats, pair, shared), graph, cluster, {f, g}, shared, inner,
                      trial);
      expect_union_of(ClusterView(pair, face_h, shared), graph, {f, g}, {h}, shared, inner, trial);
      // Past the limit, no union.
      FaceCorners three, four, five;
      ASSERT_TRUE(FaceCorners::unite(pair, face_h, {}, three));
      ASSERT_TRUE(FaceCorners::unite(three, face_f, {}, four));
      EXPECT_EQ(four.triangle_count, FaceCorners::kMaxTriangles);
      EXPECT_FALSE(FaceCorners::unite(four, face_g, {}, five));
    }
  }
}

TEST(ClusterView, FaceStatisticsAreCentred) {
  const GroundTruthShape shape = make_shape("box_with_hole", ShapeOptions{});
  const DualGraph graph(shape.mesh, VertexWeights::Area);
  for (std::uint32_t f = 0; f < graph.face_count(); f += 7) {
    const ClusterStats stats = graph.face_stats(f);
    EXPECT_EQ(stats.moments.at(1, 0, 0), 0);
    EXPECT_EQ(stats.moments.at(0, 1, 0), 0);
    EXPECT_EQ(stats.moments.at(0, 0, 1), 0);
    const Corners corners(graph, {f});
    EXPECT_LE((stats.moments.origin() - corners.centroid()).norm(), 1e-15);
    // Its corners, about the same origin, add up to the same statistics.
    FaceCorners face;
    ASSERT_TRUE(graph.face_corners(f, face));
    EXPECT_EQ(face.centroid, stats.moments.origin());
    ClusterStats from_corners;
    from_corners.moments = Moments(face.centroid);
    from_corners.add(face);
    for (int n = 0; n < Moments::kCount; ++n)
      EXPECT_NEAR(from_corners.moments.values()[n], stats.moments.values()[n], 1e-16) << n;
    expect_near(from_corners.normal_position, stats.normal_position, 1e-16, "normal position");
    expect_near(from_corners.normal_sum, stats.normal_sum, 0, "normal sum");
    EXPECT_EQ(from_corners.area, stats.area);
    EXPECT_EQ(from_corners.triangle_count, 1u);
  }
}

// Polygon faces: up to FaceCorners::kMaxTriangles triangles by their corners, with the edges
// between their own triangles; larger ones only by their statistics.
TEST(ClusterView, PolygonFacesByTheirCorners) {
  std::vector<Vec3> positions;
  for (int i = 0; i < 8; ++i)
    positions.push_back({std::cos(0.8 * i), std::sin(0.8 * i), 0.1 * std::sin(2.1 * i)});
  // A quad (2 triangles), a hexagon (4) and an octagon (6) sharing the same ring of vertices.
  const Mesh mesh = Mesh::from_polygons(positions, {0, 4, 10, 18},
                                        {0, 1, 2, 3, 0, 1, 2, 3, 4, 5, 0, 1, 2, 3, 4, 5, 6, 7});
  const DualGraph graph(mesh, VertexWeights::Area);
  for (std::uint32_t f = 0; f < 3; ++f) {
    FaceCorners face;
    const std::uint32_t triangles = graph.first_triangle(f + 1) - graph.first_triangle(f);
    ASSERT_EQ(graph.face_corners(f, face), triangles <= FaceCorners::kMaxTriangles) << f;
    if (triangles > FaceCorners::kMaxTriangles) continue;
    const ClusterStats stats = graph.face_stats(f);
    EXPECT_EQ(face.triangle_count, triangles);
    expect_near(face.edges.tensor_matrix(), stats.edges.tensor_matrix(), 0, "inner edges");
    EXPECT_GT(face.edges.tensor_matrix().cwiseAbs().maxCoeff(), 0) << f;
    expect_near(face.second_moment, stats.moments.second_moment(), 1e-15, "second moment");
  }
}

// The sphere's fit reads the second moment's whole decomposition from the view, which goes on from
// the plane's smallest pair: it must be the decomposition computed anew, bit for bit, whether the
// pair was asked for first or not, and the sphere's fit the same as from the moments alone.
TEST(ClusterView, SecondMomentDecompositionAndSphereFitAreThoseComputedAnew) {
  const Mesh mesh = testing::noisy_uniform_shape("cylinder_with_sphere_cap");
  const DualGraph graph(mesh, VertexWeights::Area);
  std::mt19937_64 rng(11);
  int solved = 0, beaten = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const std::vector<std::uint32_t> all = shuffled_faces(graph, rng);
    const std::vector<std::uint32_t> a(all.begin(), all.begin() + 4 + trial * 13);
    const ClusterStats stats = stats_of(graph, a);
    FaceCorners face;
    ASSERT_TRUE(graph.face_corners(all[200], face));
    const EdgeStats shared;
    const ClusterView reference(stats, face, shared);
    const detail::SymmetricEigen3 anew = detail::symmetric_eigen3(reference.second_moment());
    for (bool smallest_first : {true, false}) {
      const ClusterView view(stats, face, shared);
      if (smallest_first) {
        EXPECT_EQ(view.smallest_eigenvalue(), reference.smallest_eigenvalue());
      }
      const ClusterView::Eigensystem& e = view.second_moment_eigensystem();
      EXPECT_EQ(e.values, anew.values) << trial;
      EXPECT_EQ(e.vectors, anew.vectors) << trial;
    }
    detail::CentredMomentsND<3> moments;
    moments.weight = reference.weight();
    moments.second = reference.second_moment();
    moments.third = reference.radial_moments().third;
    moments.fourth = reference.radial_moments().fourth;
    const double minimum = detail::pratt_fit(moments).objective_minimum;
    for (double factor : {std::numeric_limits<double>::infinity(), 2.0, 0.5}) {
      const double beat = factor * minimum;
      const detail::PrattResult<3> from_moments =
          detail::pratt_fit(moments, beat, reference.smallest_eigenvalue());
      const ClusterView view(stats, face, shared);
      const detail::PrattResult<3> from_view = detail::pratt_fit(view, beat);
      EXPECT_EQ(from_view.valid, from_moments.valid);
      EXPECT_EQ(from_view.beaten, from_moments.beaten);
      EXPECT_EQ(from_view.error, from_moments.error);
      EXPECT_EQ(from_view.objective_minimum, from_moments.objective_minimum);
      EXPECT_EQ(from_view.radius, from_moments.radius);
      EXPECT_EQ(from_view.centre, from_moments.centre);
      ++(from_view.beaten ? beaten : solved);
    }
  }
  EXPECT_GT(solved, 40);
  EXPECT_GT(beaten, 20);
}

}  // namespace
}  // namespace primseg
