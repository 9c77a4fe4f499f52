// Incremental statistics equal a direct recomputation, whatever the merge order.
#include "primseg/cluster_stats.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include <Eigen/Geometry>

#include "primseg/dual_graph.hpp"
#include "primseg/shape_generator.hpp"

namespace primseg {
namespace {

double relative_difference(double a, double b, double scale) {
  return std::abs(a - b) / scale;
}

TEST(Moments, TranslationMatchesDirectSums) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> coordinate(-3, 3), weight(0.1, 2);
  std::vector<std::pair<Eigen::Vector3d, double>> points(50);
  for (auto& [x, w] : points) {
    x = {coordinate(rng), coordinate(rng), coordinate(rng)};
    w = weight(rng);
  }
  Moments about_a(Eigen::Vector3d(1, 2, 3));
  for (const auto& [x, w] : points) about_a.add_point(x, w);
  const Eigen::Vector3d target(-0.5, 0.25, 2);
  const Moments moved = about_a.translated(target);
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; i + j <= 4; ++j)
      for (int k = 0; i + j + k <= 4; ++k) {
        double direct = 0;
        for (const auto& [x, w] : points) {
          const Eigen::Vector3d d = x - target;
          direct += w * std::pow(d.x(), i) * std::pow(d.y(), j) * std::pow(d.z(), k);
        }
        EXPECT_NEAR(moved.at(i, j, k), direct, 1e-11 * (1 + std::abs(direct))) << i << j << k;
      }
}

TEST(ClusterStats, RandomMergeSequencesEqualTheWholeMeshStatistics) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.random_motion = true;
  const GroundTruthShape shape = make_shape("box_with_dome", options);
  const DualGraph graph(shape.mesh, VertexWeights::Uniform);
  // Direct: every triangle corner into one set of moments about the origin.
  Moments direct(Eigen::Vector3d::Zero());
  for (std::uint32_t t = 0; t < shape.mesh.triangle_count(); ++t) {
    const auto w = graph.corner_weights(t);
    for (int c = 0; c < 3; ++c) direct.add_point(graph.position(graph.corners(t)[c]), w[c]);
  }
  EdgeStats all_edges;
  for (const DualEdge& e : graph.edges()) all_edges += e.shared;
  for (std::uint32_t f = 0; f < graph.face_count(); ++f) all_edges += graph.face_stats(f).edges;

  std::mt19937_64 rng(9);
  for (int trial = 0; trial < 3; ++trial) {
    // Merge the faces in a random order into random groups, then the groups together.
    std::vector<std::uint32_t> order(graph.face_count());
    std::iota(order.begin(), order.end(), 0u);
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<ClusterStats> groups(7);
    std::vector<bool> used(7, false);
    for (std::uint32_t f : order) {
      const std::size_t g = rng() % groups.size();
      if (!used[g]) {
        groups[g] = graph.face_stats(f);
        used[g] = true;
      } else {
        groups[g].merge(graph.face_stats(f), {});
      }
    }
    ClusterStats total = groups[0];
    for (std::size_t g = 1; g < groups.size(); ++g) total.merge(groups[g], {});
    const Moments about_origin = total.moments.translated(Eigen::Vector3d::Zero());
    for (int n = 0; n < Moments::kCount; ++n)
      EXPECT_LT(relative_difference(about_origin.values()[n], direct.values()[n],
                                    1 + std::abs(direct.values()[n])),
                1e-12);
    EXPECT_EQ(total.triangle_count, shape.mesh.triangle_count());
    // The shared tensors complete the internal ones: in total, every mesh edge once.
    EdgeStats edges = total.edges;
    for (const DualEdge& e : graph.edges()) edges += e.shared;
    for (int n = 0; n < 6; ++n) EXPECT_NEAR(edges.tensor[n], all_edges.tensor[n], 1e-12);
    // The normal-position moment translates exactly too.
    const ClusterStats centred = total.centred();
    Eigen::Matrix3d np = Eigen::Matrix3d::Zero();
    // So do the face-plane moments: direct sums of A n nᵀ, A n (n·(c − o)), A (n·(c − o))².
    Eigen::Matrix3d nn = Eigen::Matrix3d::Zero();
    Eigen::Vector3d n_offset = Eigen::Vector3d::Zero();
    double offset_square = 0;
    for (std::uint32_t t = 0; t < shape.mesh.triangle_count(); ++t) {
      const Triangle tri = graph.corners(t);
      Eigen::Vector3d n = (graph.position(tri[1]) - graph.position(tri[0]))
                              .cross(graph.position(tri[2]) - graph.position(tri[0]));
      if (graph.flipped(t)) n = -n;
      const Eigen::Vector3d c =
          (graph.position(tri[0]) + graph.position(tri[1]) + graph.position(tri[2])) / 3;
      np += (c - centred.moments.origin()) * (0.5 * n).transpose();
      const double area = 0.5 * n.norm();
      const Eigen::Vector3d unit = n.normalized();
      const double offset = unit.dot(c - centred.moments.origin());
      nn += area * unit * unit.transpose();
      n_offset += area * offset * unit;
      offset_square += area * offset * offset;
    }
    EXPECT_LT((np - centred.normal_position).norm(), 1e-12);
    EXPECT_LT((nn - centred.face_planes.normal_normal_matrix()).norm(), 1e-12);
    EXPECT_LT((n_offset - centred.face_planes.normal_offset).norm(), 1e-12);
    EXPECT_NEAR(offset_square, centred.face_planes.offset_square, 1e-12);
  }
}

TEST(ClusterStats, NormalAlignmentIsOneOnAFineSphereAndLowOnAFlatCap) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.02;
  const GroundTruthShape sphere = make_shape("sphere", options);
  const DualGraph graph(sphere.mesh, VertexWeights::Area);
  ClusterStats all = graph.face_stats(0);
  for (std::uint32_t f = 1; f < graph.face_count(); ++f) all.merge(graph.face_stats(f), {});
  const Primitive& truth = sphere.regions[0];
  const Eigen::Vector3d centre = graph.frame().to_working(truth.point);
  const double radius = std::ldexp(truth.radius, -graph.frame().exponent);
  EXPECT_GT(all.normal_alignment(Eigen::Matrix3d::Identity(), centre, radius), 0.99);
  // A flat disc through the centre agrees nowhere with the sphere's normals.
  const GroundTruthShape box = make_shape("box", {});
  const DualGraph flat(box.mesh, VertexWeights::Area);
  ClusterStats top = flat.face_stats(0);
  EXPECT_LT(top.normal_alignment(Eigen::Matrix3d::Identity(), top.moments.centroid(), 1.0), 1e-9);
}

}  // namespace
}  // namespace primseg
