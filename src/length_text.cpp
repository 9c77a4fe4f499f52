#include "length_text.hpp"

#include <charconv>
#include <cmath>
#include <optional>

#include "primseg/error.hpp"

namespace primseg::detail {
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

bool is_percentage(const std::string& text) {
  return !text.empty() && text.back() == '%';
}

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

}  // namespace primseg::detail
