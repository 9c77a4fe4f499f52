// Segmentation scores on hand-made cases with known answers.
#include "primseg/evaluation.hpp"

#include <gtest/gtest.h>

#include "primseg/error.hpp"

namespace primseg {
namespace {

const auto P = PrimitiveType::Plane;
const auto C = PrimitiveType::Cylinder;

TEST(ScoreSegmentation, PerfectUpToRenumbering) {
  const std::vector<std::uint32_t> truth{0, 0, 1, 1, 2}, labels{2, 2, 0, 0, 1};
  const std::vector<double> area{1, 1, 2, 2, 3};
  const SegmentationScore s = score_segmentation(labels, truth, area, {C, P, P}, {P, C, P});
  EXPECT_DOUBLE_EQ(s.mean_iou, 1);
  EXPECT_DOUBLE_EQ(s.min_iou, 1);
  EXPECT_DOUBLE_EQ(s.type_accuracy, 1);
  EXPECT_DOUBLE_EQ(s.rand_index, 1);
  EXPECT_DOUBLE_EQ(s.area_by_type[0], 5.0 / 9);
  EXPECT_DOUBLE_EQ(s.correct_area_by_type[1], 4.0 / 9);
}

TEST(ScoreSegmentation, TwoRegionsMergedIntoOneCluster) {
  // Regions of area 1 and 3 reported as one cluster of area 4 (a plane; region 1 is a cylinder).
  const std::vector<std::uint32_t> truth{0, 1, 1, 1}, labels{0, 0, 0, 0};
  const std::vector<double> area{1, 1, 1, 1};
  const SegmentationScore s = score_segmentation(labels, truth, area, {P}, {P, C});
  // The larger region gets the cluster (IoU 3/4), the other none (0).
  EXPECT_DOUBLE_EQ(s.mean_iou, 3.0 / 8);
  EXPECT_DOUBLE_EQ(s.min_iou, 0);
  EXPECT_DOUBLE_EQ(s.type_accuracy, 0) << "the cylinder is matched to a plane";
  // Disagreeing pairs: one point in each region (2 * 1 * 3 of 16 ordered pairs).
  EXPECT_DOUBLE_EQ(s.rand_index, 1 - 6.0 / 16);
}

TEST(ScoreSegmentation, WrongTypeCostsItsArea) {
  const std::vector<std::uint32_t> truth{0, 1}, labels{0, 1};
  const SegmentationScore s = score_segmentation(labels, truth, {1, 3}, {P, P}, {P, C});
  EXPECT_DOUBLE_EQ(s.type_accuracy, 0.25);
  EXPECT_DOUBLE_EQ(s.mean_iou, 1);
}

TEST(ScoreSegmentation, RejectsMismatchedInput) {
  EXPECT_THROW(score_segmentation({0, 1}, {0}, {1, 1}, {P, P}, {P}), InvalidInputError);
  EXPECT_THROW(score_segmentation({0, 5}, {0, 0}, {1, 1}, {P}, {P}), InvalidInputError);
}

TEST(FaceAreas, SumTriangles) {
  const Mesh square = Mesh::from_polygons({{0, 0, 0}, {2, 0, 0}, {2, 3, 0}, {0, 3, 0}, {0, 0, 1}},
                                          {0, 4, 7}, {0, 1, 2, 3, 0, 1, 4});
  const std::vector<double> area = face_areas(square);
  ASSERT_EQ(area.size(), 2u);
  EXPECT_DOUBLE_EQ(area[0], 6);
  EXPECT_DOUBLE_EQ(area[1], 1);
}

}  // namespace
}  // namespace primseg
