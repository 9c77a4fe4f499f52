#include "text_scanner.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "primseg/error.hpp"

namespace primseg::mesh_io_detail {

void raise(ErrorKind kind, std::string_view file, std::string_view location,
           std::string_view reason) {
  std::string message;
  message.reserve(file.size() + location.size() + reason.size() + 4);
  message.append(file).append(": ").append(location).append(": ").append(reason);
  if (kind == ErrorKind::InvalidInput) throw InvalidInputError(message);
  throw ParseError(message);
}

std::string line_location(std::size_t line) {
  return "line " + std::to_string(line);
}

std::string offset_location(std::size_t offset) {
  return "byte offset " + std::to_string(offset);
}

std::string quote_token(const char* first, const char* last) {
  constexpr std::size_t kMaxShown = 40;
  std::string shown = "'";
  std::size_t length = 0;
  for (const char* c = first; c != last && !is_blank(*c) && *c != '\n'; ++c, ++length) {
    if (length == kMaxShown) {
      shown += "...";
      break;
    }
    const auto byte = static_cast<unsigned char>(*c);
    if (byte >= 0x20 && byte < 0x7f) {
      shown += *c;
    } else {
      static constexpr char kHex[] = "0123456789abcdef";
      shown += "\\x";
      shown += kHex[byte >> 4];
      shown += kHex[byte & 15];
    }
  }
  shown += "'";
  return shown;
}

const char* parse_double_slow(const char* first, const char* last, double& value) {
  // from_chars reports out-of-range without a value; strtod gives +-HUGE_VAL on overflow and
  // the nearest value on underflow, which is what a coordinate like 1e-400 should become.
  const auto [end, error] = std::from_chars(first, last, value);
  if (error != std::errc::result_out_of_range) return error == std::errc{} ? end : nullptr;
  const std::string copy(first, end);
  errno = 0;
  value = std::strtod(copy.c_str(), nullptr);
  return end;
}

std::size_t TextScanner::line_of(const char* where) const {
  return 1 + static_cast<std::size_t>(std::count(begin_, std::min(where, end_), '\n'));
}

void TextScanner::fail_at(const char* where, std::string_view reason, ErrorKind kind) const {
  raise(kind, file_name_, line_location(line_of(where)), reason);
}

void TextScanner::fail_at_token(std::string_view expectation, ErrorKind kind) const {
  std::string reason(expectation);
  if (token_ == end_) {
    reason += ", found end of file";
  } else if (*token_ == '\n') {
    reason += ", found end of line";
  } else {
    reason += ", found " + quote_token(token_, end_);
  }
  fail_at(token_, reason, kind);
}

bool equals_ignoring_case(std::string_view token, std::string_view keyword) {
  if (token.size() != keyword.size()) return false;
  for (std::size_t i = 0; i < token.size(); ++i) {
    char c = token[i];
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    char k = keyword[i];
    if (k >= 'A' && k <= 'Z') k = static_cast<char>(k - 'A' + 'a');
    if (c != k) return false;
  }
  return true;
}

}  // namespace primseg::mesh_io_detail
