#pragma once
// A length as the CLI and the Python module take it: "T" in input units or "T%" of the
// bounding-box diagonal (--tolerance, --relation-length-tolerance, relation_length_tolerance="T%").
// One parser, so that every interface turns a percentage into the same double.

#include <string>
#include <string_view>

namespace primseg::detail {

/// Whether `text` ends in '%' (a percentage of the bounding-box diagonal).
bool is_percentage(const std::string& text);

/// What is wrong with a length parse_length() refuses (without the option's name); empty when it
/// accepts it: a finite non-negative number, optionally followed by '%'.
std::string length_syntax_error(const std::string& text);

/// `text` in input units: the number itself, or for "T%" T / 100 × `bounding_box_diagonal`.
/// Throws InvalidInputError "`option`: ..." when length_syntax_error(text) is not empty.
double parse_length(const std::string& text, double bounding_box_diagonal, std::string_view option);

}  // namespace primseg::detail
