// Cuts: every level in O(F), labels ordered by area, reports with exact distances.
#include "primseg/cut.hpp"

#include <gtest/gtest.h>

#include <set>

#include "primseg/error.hpp"
#include "primseg/shape_generator.hpp"

namespace primseg {
namespace {

TEST(Cut, EveryCountFromOneToFGivesThatManyClustersOrderedByArea) {
  const GroundTruthShape shape = make_shape("stepped_block", {});
  const Hierarchy h = build_hierarchy(shape.mesh);
  for (std::uint32_t k = 1; k <= h.face_count(); ++k) {
    const Segmentation seg = cut_by_count(h, k);
    ASSERT_EQ(seg.cluster_count(), k);
    EXPECT_EQ(std::set<std::uint32_t>(seg.labels.begin(), seg.labels.end()).size(), k);
    const auto reports = describe_clusters(h, seg);
    for (std::size_t c = 1; c < reports.size(); ++c)
      EXPECT_GE(reports[c - 1].area, reports[c].area);
    std::uint32_t faces = 0;
    for (const auto& r : reports) faces += r.face_count;
    EXPECT_EQ(faces, h.face_count());
  }
  EXPECT_THROW(cut_by_count(h, 0), InvalidInputError);
  EXPECT_THROW(cut_by_count(h, h.face_count() + 1), InvalidInputError);
}

TEST(Cut, ToleranceKeepsNodesWhoseRmsEstimateFits) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.noise = 0.001;
  const GroundTruthShape shape = make_shape("box_with_boss", options);
  const Hierarchy h = build_hierarchy(shape.mesh);
  std::uint32_t previous = h.face_count() + 1;
  for (double tolerance : {0.0, 1e-4, 1e-3, 1e-2, 1e-1, 1e3}) {
    const Segmentation seg = cut_by_tolerance(h, tolerance);
    for (std::uint32_t node : seg.nodes) {
      if (!h.is_leaf(node)) {
        EXPECT_LE(h.rms_estimate(node), tolerance);
      }
    }
    EXPECT_LE(seg.cluster_count(), previous);  // looser tolerance, fewer clusters
    previous = seg.cluster_count();
  }
  EXPECT_EQ(cut_by_tolerance(h, 1e3).cluster_count(), 1u);
  EXPECT_THROW(cut_by_tolerance(h, -1), InvalidInputError);
}

TEST(Cut, ReportsExactDistancesToTheFittedPrimitive) {
  const GroundTruthShape shape = make_shape("box_with_hole", {});
  const Hierarchy h = build_hierarchy(shape.mesh);
  const auto reports = describe_clusters(h, cut_by_count(h, 7));
  for (const ClusterReport& r : reports) {
    EXPECT_LT(r.max, 1e-9);
    EXPECT_LE(r.rms, r.max + 1e-15);
    if (r.primitive.type == PrimitiveType::Cylinder) {
      const Primitive* truth = nullptr;
      for (const Primitive& p : shape.regions)
        if (p.type == PrimitiveType::Cylinder) truth = &p;
      ASSERT_NE(truth, nullptr);
      EXPECT_NEAR(r.primitive.radius, truth->radius, 1e-9 * truth->radius);
    }
  }
}

}  // namespace
}  // namespace primseg
