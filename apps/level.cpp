#include "level.hpp"

#include <charconv>
#include <cmath>

#include "primseg/error.hpp"

namespace primseg::cli {

double parse_tolerance(const std::string& text, double bounding_box_diagonal) {
  const bool percent = !text.empty() && text.back() == '%';
  const std::string number = percent ? text.substr(0, text.size() - 1) : text;
  double value = 0;
  const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
  if (number.empty() || error != std::errc() || end != number.data() + number.size() ||
      !std::isfinite(value) || value < 0)
    throw InvalidInputError("--tolerance: '" + text +
                            "' is not a non-negative number (optionally followed by %)");
  return percent ? value / 100 * bounding_box_diagonal : value;
}

void validate_level(const LevelChoice& level, std::uint32_t face_count) {
  if (level.clusters && (*level.clusters < 1 || *level.clusters > face_count))
    throw InvalidInputError("--clusters: must be between 1 and the number of faces (" +
                            std::to_string(face_count) + "), not " +
                            std::to_string(*level.clusters));
  if (level.tolerance) parse_tolerance(*level.tolerance, 1.0);
}

Segmentation cut(const Hierarchy& hierarchy, const LevelChoice& level) {
  if (level.clusters) return cut_by_count(hierarchy, *level.clusters);
  const std::string tolerance = level.tolerance.value_or(kDefaultTolerance);
  return cut_by_tolerance(hierarchy,
                          parse_tolerance(tolerance, bounding_box_diagonal(hierarchy.mesh())));
}

}  // namespace primseg::cli
