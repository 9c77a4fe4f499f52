// A view of the union of two clusters gives what a direct computation over the union's points
// gives, without forming the union's moments; a view of one cluster gives that cluster's.
#include "primseg/cluster_view.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <numeric>
#include <random>

#include "primseg/dual_graph.hpp"
#include "primseg/shape_generator.hpp"

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
          points.push_back(graph.position(graph.mesh().triangles[t][c]));
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

TEST(ClusterView, UnionQuantitiesEqualDirectSumsOverTheUnionsPoints) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.noise = 0.003;
  options.random_motion = true;
  const GroundTruthShape shape = make_shape("cylinder_with_sphere_cap", options);
  for (VertexWeights weights : {VertexWeights::Area, VertexWeights::Uniform}) {
    const DualGraph graph(shape.mesh, weights);
    std::mt19937_64 rng(3);
    // Two disjoint random sets of faces (adjacency does not matter for the moments).
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<std::uint32_t> all(graph.face_count());
      std::iota(all.begin(), all.end(), 0u);
      std::shuffle(all.begin(), all.end(), rng);
      const std::size_t na = 1 + trial * 37, nb = 1 + trial * 11;
      const std::vector<std::uint32_t> a(all.begin(), all.begin() + na);
      const std::vector<std::uint32_t> b(all.begin() + na, all.begin() + na + nb);
      std::vector<std::uint32_t> both = a;
      both.insert(both.end(), b.begin(), b.end());
      const ClusterStats stats_a = stats_of(graph, a), stats_b = stats_of(graph, b);
      EdgeStats shared;
      shared.add_edge(Eigen::Vector3d(0.1, 0.2, 0.3), 0.4);
      const ClusterView view(stats_a, stats_b, shared);
      const Corners corners(graph, both);
      const double scale = corners.sum([](const Eigen::Vector3d& y) { return y.squaredNorm(); });

      EXPECT_NEAR(view.weight(), corners.sum([](const Eigen::Vector3d&) { return 1.0; }),
                  1e-12 * view.weight());
      expect_near(view.centroid(), corners.centroid(), 1e-13, "centroid");
      expect_near(view.second_moment(),
                  corners.sum([](const Eigen::Vector3d& y) -> Eigen::Matrix3d {
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
      EXPECT_DOUBLE_EQ(view.area(), stats_a.area + stats_b.area);
      Eigen::Matrix3d tensor =
          stats_a.edges.tensor_matrix() + stats_b.edges.tensor_matrix() + shared.tensor_matrix();
      expect_near(view.edge_tensor(), tensor, 1e-14, "edge tensor");

      // The view's whole statistics equal the old way of forming them (merge, then centre), and
      // the single view of them gives the same quantities.
      ClusterStats merged = stats_a;
      merged.merge(stats_b, shared);
      merged = merged.centred();
      const ClusterStats& formed = view.stats();
      for (int n = 0; n < Moments::kCount; ++n)
        EXPECT_NEAR(formed.moments.values()[n], merged.moments.values()[n],
                    1e-12 * scale * (1 + radius * radius))
            << n;
      expect_near(formed.normal_position, merged.normal_position, 1e-13 * view.area(),
                  "normal position");
      const ClusterView single(formed);
      expect_near(single.second_moment(), view.second_moment(), 1e-13 * scale, "single view");
      const Eigen::Matrix3d q = Eigen::Matrix3d::Identity() -
                                Eigen::Vector3d::UnitZ() * Eigen::Vector3d::UnitZ().transpose();
      const Eigen::Vector3d point = view.centroid() + Eigen::Vector3d(0.3, -0.2, 0.1);
      EXPECT_NEAR(view.normal_alignment(q, point, 0.7), merged.normal_alignment(q, point, 0.7),
                  1e-12);
      EXPECT_NEAR(single.normal_alignment(q, point, 0.7), merged.normal_alignment(q, point, 0.7),
                  1e-12);
      // With degree 2 only, the moments up to degree 2 are the same bits and the rest zero.
      const ClusterStats low = view.stats(2);
      for (int n = 0; n < Moments::kCount; ++n)
        EXPECT_EQ(low.moments.values()[n],
                  n < Moments::kCountUpToDegree2 ? formed.moments.values()[n] : 0.0)
            << n;
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
  }
}

}  // namespace
}  // namespace primseg
