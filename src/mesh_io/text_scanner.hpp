#pragma once
// Private to the mesh readers: error reporting with file locations, number parsing, and the
// tokenizer every text format (OFF, OBJ, ascii PLY, ascii STL) shares.

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <system_error>

namespace primseg::mesh_io_detail {

enum class ErrorKind {
  Parse,         // primseg::ParseError: the bytes do not form a valid file.
  InvalidInput,  // primseg::InvalidInputError: valid syntax, unusable values (NaN, no faces).
};

/// Throws "<file>: <location>: <reason>" as the exception `kind` names.
[[noreturn]] void raise(ErrorKind kind, std::string_view file, std::string_view location,
                        std::string_view reason);
std::string line_location(std::size_t line);
std::string offset_location(std::size_t offset);

/// Shortened, printable copy of the token starting at `first`, for error messages.
std::string quote_token(const char* first, const char* last);

/// Parses a decimal floating-point number (std::from_chars syntax plus a leading '+'; "nan" and
/// "inf" parse to non-finite values). Overflow gives +-inf, underflow the nearest representable
/// value. Returns the end of the number, or nullptr if [first, last) does not start with one.
const char* parse_double_slow(const char* first, const char* last, double& value);
inline const char* parse_double(const char* first, const char* last, double& value) {
  if (first != last && *first == '+') ++first;
  const auto [end, error] = std::from_chars(first, last, value);
  if (error == std::errc{}) return end;
  if (error == std::errc::result_out_of_range) return parse_double_slow(first, last, value);
  return nullptr;
}

/// Parses a decimal integer with optional sign; nullptr if there is none or it overflows.
inline const char* parse_integer(const char* first, const char* last, std::int64_t& value) {
  if (first != last && *first == '+') ++first;
  const auto [end, error] = std::from_chars(first, last, value);
  return error == std::errc{} ? end : nullptr;
}

inline bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/// Cursor over a text file held in memory. Tokens are separated by blanks and, unless the scanner
/// is line-bounded (OBJ: one statement per line), by newlines. Line numbers are only computed when
/// an error is reported, which keeps the hot path to pointer increments.
class TextScanner {
 public:
  struct Options {
    /// Tokens never continue on the next line; skip_line() moves on.
    bool line_bounded = false;
    /// Character that starts a comment running to the end of its line; '\0' for none.
    char comment = '\0';
  };

  TextScanner(std::span<const char> text, std::string_view file_name, Options options)
      : begin_(text.data()),
        cursor_(text.data()),
        end_(text.data() + text.size()),
        token_(text.data()),
        file_name_(file_name),
        options_(options) {}

  std::string_view file_name() const { return file_name_; }
  const char* begin() const { return begin_; }
  const char* cursor() const { return cursor_; }
  const char* end() const { return end_; }
  void set_cursor(const char* cursor) { cursor_ = cursor; }
  std::size_t remaining() const { return static_cast<std::size_t>(end_ - cursor_); }

  /// Skips separators (and comments): afterwards the cursor is at a token, at the end of the
  /// text or, when line-bounded, at the end of the line.
  void skip_separators() {
    while (cursor_ != end_) {
      const char c = *cursor_;
      if (is_blank(c) || (c == '\n' && !options_.line_bounded)) {
        ++cursor_;
      } else if (c == options_.comment && c != '\0') {
        skip_to_line_end();
      } else {
        return;
      }
    }
  }
  /// Skips blanks but never a newline or comment: is another token on this line?
  bool token_follows_on_line() {
    while (cursor_ != end_ && is_blank(*cursor_)) ++cursor_;
    return cursor_ != end_ && *cursor_ != '\n' && !(*cursor_ == options_.comment && c_set());
  }
  /// True if no token is left (in the line, when line-bounded); skips separators.
  bool at_end_of_statement() {
    skip_separators();
    return cursor_ == end_ || *cursor_ == '\n';
  }
  bool at_end() {
    skip_separators();
    return cursor_ == end_;
  }
  void skip_to_line_end() {
    while (cursor_ != end_ && *cursor_ != '\n') ++cursor_;
  }
  /// Moves past the end of the current line (ignoring whatever is left in it).
  void skip_line() {
    skip_to_line_end();
    if (cursor_ != end_) ++cursor_;
  }

  /// Next token (empty at the end of the text or line-bounded line).
  std::string_view read_token() {
    skip_separators();
    token_ = cursor_;
    while (cursor_ != end_ && !is_separator(*cursor_)) ++cursor_;
    return {token_, static_cast<std::size_t>(cursor_ - token_)};
  }

  /// Reads a whole-token number; false (cursor at the token) if the next token is not one.
  bool read_double(double& value) {
    skip_separators();
    token_ = cursor_;
    const char* end = parse_double(cursor_, end_, value);
    if (end == nullptr || (end != end_ && !is_separator(*end))) return false;
    cursor_ = end;
    return true;
  }
  bool read_integer(std::int64_t& value) {
    skip_separators();
    token_ = cursor_;
    const char* end = parse_integer(cursor_, end_, value);
    if (end == nullptr || (end != end_ && !is_separator(*end))) return false;
    cursor_ = end;
    return true;
  }

  /// Start of the token read last (also set by a failed read), for error messages.
  const char* last_token() const { return token_; }

  std::size_t line_of(const char* where) const;

  /// Reports an error at the line of `where`.
  [[noreturn]] void fail_at(const char* where, std::string_view reason,
                            ErrorKind kind = ErrorKind::Parse) const;
  /// Reports an error at the last token: "<reason>, found '<token>'" (or "found end of file").
  [[noreturn]] void fail_at_token(std::string_view expectation,
                                  ErrorKind kind = ErrorKind::Parse) const;

  bool is_separator(char c) const {
    return is_blank(c) || c == '\n' || (c == options_.comment && c != '\0');
  }

 private:
  bool c_set() const { return options_.comment != '\0'; }

  const char* begin_;
  const char* cursor_;
  const char* end_;
  const char* token_;
  std::string_view file_name_;
  Options options_;
};

/// True if `token` equals `keyword` ignoring ASCII case.
bool equals_ignoring_case(std::string_view token, std::string_view keyword);

/// Refuses a header count whose data could not fit in the bytes left, before anything is
/// allocated for it: `count` items of at least `min_bytes_each` bytes need count * min_bytes_each
/// bytes, less `slack` (a last item without trailing separator).
inline bool count_fits(std::uint64_t count, std::uint64_t min_bytes_each, std::size_t bytes_left,
                       std::uint64_t slack = 0) {
  if (count == 0) return true;
  if (min_bytes_each == 0) return count <= std::numeric_limits<std::uint32_t>::max();
  return count <= (static_cast<std::uint64_t>(bytes_left) + slack) / min_bytes_each;
}

}  // namespace primseg::mesh_io_detail
