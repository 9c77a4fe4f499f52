#include "primseg/evaluation.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <string>

#include "primseg/error.hpp"

namespace primseg {
namespace {

// Minimum-cost assignment of rows to columns (rows <= columns), O(n² m): the classic
// potentials formulation of the Hungarian method. Returns the column of each row.
std::vector<int> hungarian(const std::vector<std::vector<double>>& cost) {
  const int n = static_cast<int>(cost.size()), m = static_cast<int>(cost[0].size());
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0), v(m + 1, 0), way_cost(m + 1);
  std::vector<int> match(m + 1, 0), way(m + 1, 0);
  for (int row = 1; row <= n; ++row) {
    match[0] = row;
    int column = 0;
    std::fill(way_cost.begin(), way_cost.end(), inf);
    std::vector<char> used(m + 1, 0);
    do {
      used[column] = 1;
      const int r = match[column];
      double delta = inf;
      int next = 0;
      for (int c = 1; c <= m; ++c) {
        if (used[c]) continue;
        const double reduced = cost[r - 1][c - 1] - u[r] - v[c];
        if (reduced < way_cost[c]) {
          way_cost[c] = reduced;
          way[c] = column;
        }
        if (way_cost[c] < delta) {
          delta = way_cost[c];
          next = c;
        }
      }
      for (int c = 0; c <= m; ++c) {
        if (used[c]) {
          u[match[c]] += delta;
          v[c] -= delta;
        } else {
          way_cost[c] -= delta;
        }
      }
      column = next;
    } while (match[column] != 0);
    do {
      const int previous = way[column];
      match[column] = match[previous];
      column = previous;
    } while (column);
  }
  std::vector<int> column_of_row(n, -1);
  for (int c = 1; c <= m; ++c)
    if (match[c]) column_of_row[match[c] - 1] = c - 1;
  return column_of_row;
}

}  // namespace

SegmentationScore score_segmentation(const std::vector<std::uint32_t>& labels,
                                     const std::vector<std::uint32_t>& truth,
                                     const std::vector<double>& face_area,
                                     const std::vector<PrimitiveType>& types,
                                     const std::vector<PrimitiveType>& truth_types) {
  if (labels.size() != truth.size() || labels.size() != face_area.size())
    throw InvalidInputError("score_segmentation: labels (" + std::to_string(labels.size()) +
                            "), truth (" + std::to_string(truth.size()) + ") and areas (" +
                            std::to_string(face_area.size()) + ") differ in size");
  const std::size_t regions = truth_types.size(), clusters = types.size();
  for (std::size_t f = 0; f < labels.size(); ++f)
    if (labels[f] >= clusters || truth[f] >= regions)
      throw InvalidInputError("score_segmentation: face " + std::to_string(f) +
                              " has a label beyond the types given");
  SegmentationScore score;
  if (regions == 0) return score;
  std::vector<std::vector<double>> overlap(regions, std::vector<double>(clusters, 0.0));
  std::vector<double> region_area(regions, 0.0), cluster_area(clusters, 0.0);
  double total_area = 0;
  for (std::size_t f = 0; f < labels.size(); ++f) {
    overlap[truth[f]][labels[f]] += face_area[f];
    region_area[truth[f]] += face_area[f];
    cluster_area[labels[f]] += face_area[f];
    total_area += face_area[f];
  }
  auto iou = [&](std::size_t r, std::size_t c) {
    const double union_area = region_area[r] + cluster_area[c] - overlap[r][c];
    return union_area > 0 ? overlap[r][c] / union_area : 0.0;
  };
  // Pad with empty clusters so every region gets a column.
  const std::size_t columns = std::max(regions, clusters);
  std::vector<std::vector<double>> cost(regions, std::vector<double>(columns, 0.0));
  for (std::size_t r = 0; r < regions; ++r)
    for (std::size_t c = 0; c < clusters; ++c) cost[r][c] = -overlap[r][c];
  const std::vector<int> match = hungarian(cost);
  score.min_iou = 1;
  double typed_area = 0;
  for (std::size_t r = 0; r < regions; ++r) {
    const int c = match[r];
    const bool matched = c >= 0 && std::size_t(c) < clusters;
    const double value = matched ? iou(r, std::size_t(c)) : 0.0;
    score.mean_iou += value / double(regions);
    score.min_iou = std::min(score.min_iou, value);
    const auto type = static_cast<std::size_t>(truth_types[r]);
    score.area_by_type[type] += region_area[r];
    if (matched && types[std::size_t(c)] == truth_types[r]) {
      typed_area += region_area[r];
      score.correct_area_by_type[type] += region_area[r];
    }
  }
  for (std::size_t t = 0; t < score.area_by_type.size() && total_area > 0; ++t) {
    score.area_by_type[t] /= total_area;
    score.correct_area_by_type[t] /= total_area;
  }
  // Over the same per-region sums as typed_area, so that all regions right gives exactly 1.
  double region_total = 0;
  for (double a : region_area) region_total += a;
  score.type_accuracy = region_total > 0 ? typed_area / region_total : 0;
  // Pairs (with replacement) that disagree: same region but different clusters, or the reverse.
  double same_region = 0, same_cluster = 0, same_both = 0;
  for (std::size_t r = 0; r < regions; ++r) {
    same_region += region_area[r] * region_area[r];
    for (std::size_t c = 0; c < clusters; ++c) same_both += overlap[r][c] * overlap[r][c];
  }
  for (std::size_t c = 0; c < clusters; ++c) same_cluster += cluster_area[c] * cluster_area[c];
  score.rand_index =
      total_area > 0 ? 1 - (same_region + same_cluster - 2 * same_both) / (total_area * total_area)
                     : 0;
  return score;
}

std::vector<double> face_areas(const Mesh& mesh) {
  std::vector<double> area(mesh.face_count(), 0.0);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d a(mesh.positions[tri[0]].data()), b(mesh.positions[tri[1]].data()),
        c(mesh.positions[tri[2]].data());
    area[mesh.face_of_triangle[t]] += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

}  // namespace primseg
