#include "level.hpp"

#include <charconv>
#include <optional>
#include <string>

#include "../src/length_text.hpp"
#include "primseg/error.hpp"

namespace primseg::cli {

double parse_tolerance(const std::string& text, double bounding_box_diagonal) {
  return detail::parse_length(text, bounding_box_diagonal, "--tolerance");
}

std::optional<std::uint32_t> parse_cluster_count(const std::string& text) {
  if (text == "auto") return std::nullopt;
  std::uint32_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size())
    throw InvalidInputError("--clusters: '" + text +
                            "' is neither a number of clusters (1..F) nor 'auto'");
  return value;
}

void validate_level(const LevelChoice& level, std::uint32_t face_count) {
  if (level.clusters) {
    const auto count = parse_cluster_count(*level.clusters);
    if (count && (*count < 1 || *count > face_count))
      throw InvalidInputError("--clusters: must be between 1 and the number of faces (" +
                              std::to_string(face_count) + "), not " + std::to_string(*count));
  }
  if (level.tolerance) parse_tolerance(*level.tolerance, 1.0);
}

ChosenLevel cut(const Hierarchy& hierarchy, const LevelChoice& level) {
  if (level.clusters) {
    if (const auto count = parse_cluster_count(*level.clusters))
      return {cut_by_count(hierarchy, *count), std::nullopt, std::nullopt};
    AutoLevel automatic = choose_level(hierarchy);
    Segmentation segmentation = cut_by_count(hierarchy, automatic.clusters);
    return {std::move(segmentation), std::move(automatic), std::nullopt};
  }
  const std::string tolerance = level.tolerance.value_or(kDefaultTolerance);
  return {cut_by_tolerance(hierarchy,
                           parse_tolerance(tolerance, bounding_box_diagonal(hierarchy.mesh()))),
          std::nullopt, std::nullopt};
}

}  // namespace primseg::cli
