#pragma once
/// @file evaluation.hpp
/// Quality of a segmentation against ground-truth regions (for example those of
/// shape_generator.hpp): the scores of `primseg eval` and of the test suite.

#include <array>
#include <cstdint>
#include <vector>

#include "primseg/mesh.hpp"
#include "primseg/primitive.hpp"

namespace primseg {

/// Agreement of a segmentation with the ground truth, every figure in [0, 1] (1 = perfect).
struct SegmentationScore {
  /// Mean over ground-truth regions of the IoU (by area) with the cluster matched to it; regions
  /// are matched one-to-one to clusters by the Hungarian method maximising the total overlap
  /// area, and a region left without a cluster scores 0.
  double mean_iou = 0;
  double min_iou = 0;  ///< IoU of the worst-matched region
  /// Area-weighted fraction of the regions whose matched cluster has the region's type.
  double type_accuracy = 0;
  /// Area-weighted Rand index: the probability that two surface points drawn independently
  /// with uniform area density are either in one region and one cluster, or in different
  /// regions and different clusters.
  double rand_index = 0;
  /// Fraction of the total area in regions of each type, indexed by PrimitiveType.
  std::array<double, kPrimitiveTypeCount> area_by_type{};
  /// Fraction of the total area in regions of each type whose match has the right type: the
  /// type accuracy of type t is correct_area_by_type[t] / area_by_type[t].
  std::array<double, kPrimitiveTypeCount> correct_area_by_type{};
};

/// Scores `labels` (cluster of each face, shape (F), values < types.size()) against `truth`
/// (region of each face, shape (F), values < truth_types.size()). `face_area` has shape (F), any
/// units; `types` is the reported type of each cluster and `truth_types` of each region.
/// Throws InvalidInputError for mismatched sizes or out-of-range labels.
SegmentationScore score_segmentation(const std::vector<std::uint32_t>& labels,
                                     const std::vector<std::uint32_t>& truth,
                                     const std::vector<double>& face_area,
                                     const std::vector<PrimitiveType>& types,
                                     const std::vector<PrimitiveType>& truth_types);

/// Area of each input face of a mesh (sum of its triangles' areas), shape (F), input units².
std::vector<double> face_areas(const Mesh& mesh);

}  // namespace primseg
