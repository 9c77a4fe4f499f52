#pragma once
// How a Segmentation numbers its clusters, in one place: cut_by_count(), cut_by_tolerance(), a
// denoiser's snapped level and LevelRegularizer's levels must agree on it to the bit.

#include <algorithm>
#include <vector>

namespace primseg::detail {

/// Sorts cluster indices into label order: by decreasing area, ties by lowest face (each
/// cluster's own, so the order is total). `area(c)` and `lowest_face(c)` give cluster c's.
template <typename Index, typename Area, typename LowestFace>
void sort_into_label_order(std::vector<Index>& clusters, const Area& area,
                           const LowestFace& lowest_face) {
  std::sort(clusters.begin(), clusters.end(), [&](Index a, Index b) {
    if (area(a) != area(b)) return area(a) > area(b);
    return lowest_face(a) < lowest_face(b);
  });
}

}  // namespace primseg::detail
