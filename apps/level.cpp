#include "level.hpp"

#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include "primseg/error.hpp"

namespace primseg::cli {

bool is_percentage(const std::string& text) {
  return !text.empty() && text.back() == '%';
}

namespace {

// The number of a length "T" or "T%", if it is finite and non-negative.
std::optional<double> length_number(const std::string& text) {
  const std::size_t size = text.size() - (is_percentage(text) ? 1 : 0);
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + size, value);
  if (size == 0 || error != std::errc() || end != text.data() + size || !std::isfinite(value) ||
      value < 0)
    return std::nullopt;
  return value;
}

}  // namespace

std::string length_syntax_error(const std::string& text) {
  if (length_number(text)) return {};
  return "'" + text + "' is not a non-negative number (optionally followed by %)";
}

double parse_length(const std::string& text, double bounding_box_diagonal,
                    std::string_view option) {
  const std::optional<double> value = length_number(text);
  if (!value) throw InvalidInputError(std::string(option) + ": " + length_syntax_error(text));
  return is_percentage(text) ? *value / 100 * bounding_box_diagonal : *value;
}

double parse_tolerance(const std::string& text, double bounding_box_diagonal) {
  return parse_length(text, bounding_box_diagonal, "--tolerance");
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
