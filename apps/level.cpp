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

Segmentation cut(const Hierarchy& hierarchy, const LevelChoice& level) {
  if (level.clusters) return cut_by_count(hierarchy, *level.clusters);
  const std::string tolerance = level.tolerance.value_or(kDefaultTolerance);
  return cut_by_tolerance(hierarchy,
                          parse_tolerance(tolerance, bounding_box_diagonal(hierarchy.mesh())));
}

}  // namespace primseg::cli
