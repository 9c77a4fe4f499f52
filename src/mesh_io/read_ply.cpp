#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "binary_reader.hpp"
#include "huge_pages.hpp"
#include "readers.hpp"
#include "text_scanner.hpp"

namespace primseg::mesh_io_detail {
namespace {

enum class PlyFormat { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct Property {
  std::string_view name;
  ScalarType type = ScalarType::Float32;  // Of the value, or of the list items.
  bool is_list = false;
  ScalarType count_type = ScalarType::UInt8;
};

struct Element {
  std::string_view name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  const char* header_line = nullptr;  // For errors about the declaration.
};

std::optional<ScalarType> scalar_type_from_name(std::string_view name) {
  struct Alias {
    std::string_view name;
    ScalarType type;
  };
  static constexpr Alias kAliases[] = {
      {"char", ScalarType::Int8},      {"int8", ScalarType::Int8},
      {"uchar", ScalarType::UInt8},    {"uint8", ScalarType::UInt8},
      {"short", ScalarType::Int16},    {"int16", ScalarType::Int16},
      {"ushort", ScalarType::UInt16},  {"uint16", ScalarType::UInt16},
      {"int", ScalarType::Int32},      {"int32", ScalarType::Int32},
      {"uint", ScalarType::UInt32},    {"uint32", ScalarType::UInt32},
      {"float", ScalarType::Float32},  {"float32", ScalarType::Float32},
      {"double", ScalarType::Float64}, {"float64", ScalarType::Float64},
  };
  for (const Alias& alias : kAliases) {
    if (alias.name == name) return alias.type;
  }
  return std::nullopt;
}

/// A list length or vertex index stored in any PLY type: must be a whole number in [0, limit).
bool to_index(double value, std::uint64_t limit, std::uint64_t& index) {
  if (!(value >= 0.0) || !(value < static_cast<double>(limit))) return false;
  index = static_cast<std::uint64_t>(value);
  return static_cast<double>(index) == value;
}

std::string describe_value(double value) {
  if (value == std::floor(value) && std::fabs(value) < 1e18) {
    return std::to_string(static_cast<long long>(value));
  }
  // Shortest round-trip form: 1.5, not 1.500000 (and not 0.000000 for 1e-9).
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

/// Where a face error is reported: a line of the ascii body or an offset of the binary one.
struct ErrorSite {
  const TextScanner* text = nullptr;
  const char* position = nullptr;
  const BinaryReader* binary = nullptr;
  std::size_t offset = 0;

  [[noreturn]] void fail(const std::string& reason) const {
    if (text != nullptr) text->fail_at(position, reason);
    binary->fail_at(offset, reason);
  }
};

class PlyReader {
 public:
  PlyReader(std::span<const char> bytes, std::string_view file_name)
      : bytes_(bytes), text_(bytes, file_name, {.line_bounded = true, .comment = '\0'}) {}

  Mesh read() {
    read_header();
    find_roles();
    check_sizes();
    if (format_ == PlyFormat::Ascii) {
      read_ascii_body();
    } else {
      read_binary_body();
    }
    return to_mesh(std::move(soup_));
  }

 private:
  static constexpr std::uint64_t kMaxCount = std::numeric_limits<std::uint32_t>::max();

  // ---- Header -----------------------------------------------------------------------------

  void read_header() {
    if (bytes_.empty()) text_.fail_at(text_.cursor(), "file is empty");
    if (text_.read_token() != "ply" || !text_.at_end_of_statement()) {
      text_.fail_at(text_.begin(), "not a PLY file: the first line is not 'ply'");
    }
    text_.skip_line();
    bool has_format = false;
    while (true) {
      if (text_.cursor() == text_.end()) {
        text_.fail_at(text_.cursor(), "file ends inside the header (no 'end_header' line)");
      }
      const std::string_view keyword = text_.read_token();
      const char* line = text_.last_token();
      if (keyword == "end_header") {
        if (!text_.at_end_of_statement()) text_.fail_at(line, "text after 'end_header'");
        text_.skip_line();
        break;
      }
      if (keyword == "format") {
        const std::string_view name = text_.read_token();
        if (name == "ascii") {
          format_ = PlyFormat::Ascii;
        } else if (name == "binary_little_endian") {
          format_ = PlyFormat::BinaryLittleEndian;
        } else if (name == "binary_big_endian") {
          format_ = PlyFormat::BinaryBigEndian;
        } else {
          text_.fail_at_token("expected ascii, binary_little_endian or binary_big_endian");
        }
        has_format = true;
      } else if (keyword == "element") {
        read_element_declaration(line);
      } else if (keyword == "property") {
        read_property_declaration(line);
      } else if (keyword != "comment" && keyword != "obj_info" && !keyword.empty()) {
        text_.fail_at(line, "unknown header line " + quote_token(line, text_.end()));
      }
      text_.skip_line();
    }
    if (!has_format) text_.fail_at(text_.begin(), "the header has no 'format' line");
    body_ = text_.cursor();
  }

  void read_element_declaration(const char* line) {
    Element element;
    element.header_line = line;
    element.name = text_.read_token();
    if (element.name.empty()) text_.fail_at_token("expected an element name");
    std::int64_t count = 0;
    if (!text_.read_integer(count) || count < 0) {
      text_.fail_at_token("expected the record count of element '" + std::string(element.name) +
                          "'");
    }
    element.count = static_cast<std::uint64_t>(count);
    elements_.push_back(std::move(element));
  }

  ScalarType read_type() {
    const std::optional<ScalarType> type = scalar_type_from_name(text_.read_token());
    if (!type) text_.fail_at_token("expected a property type (char, uchar, ..., float, double)");
    return *type;
  }

  void read_property_declaration(const char* line) {
    if (elements_.empty()) text_.fail_at(line, "property declared before any element");
    Property property;
    if (text_.read_token() == "list") {
      property.is_list = true;
      property.count_type = read_type();
    } else {
      text_.set_cursor(text_.last_token());
    }
    property.type = read_type();
    property.name = text_.read_token();
    if (property.name.empty()) text_.fail_at_token("expected a property name");
    elements_.back().properties.push_back(property);
  }

  /// Which element and properties hold the vertices and faces.
  void find_roles() {
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      const Element& element = elements_[e];
      if (element.name == "vertex" && !vertex_element_) {
        vertex_element_ = e;
        for (std::size_t axis = 0; axis < 3; ++axis) {
          const std::string_view axis_name = std::string_view("xyz").substr(axis, 1);
          for (std::size_t p = 0; p < element.properties.size(); ++p) {
            if (element.properties[p].name == axis_name && !element.properties[p].is_list) {
              coordinate_property_[axis] = p;
            }
          }
          if (coordinate_property_[axis] == kNone) {
            text_.fail_at(element.header_line, "element 'vertex' has no scalar property '" +
                                                   std::string(axis_name) + "'");
          }
        }
        if (element.count > kMaxCount) {
          text_.fail_at(element.header_line, "too many vertices: " + std::to_string(element.count));
        }
      } else if (element.name == "face" && !face_element_) {
        face_element_ = e;
        for (std::size_t p = 0; p < element.properties.size(); ++p) {
          const Property& property = element.properties[p];
          if (property.name == "vertex_indices" || property.name == "vertex_index") {
            if (!property.is_list) {
              text_.fail_at(element.header_line,
                            "face property '" + std::string(property.name) + "' is not a list");
            }
            index_property_ = p;
          }
        }
        if (index_property_ == kNone) {
          text_.fail_at(element.header_line,
                        "element 'face' has no 'vertex_indices' list property");
        }
        if (element.count > kMaxCount) {
          text_.fail_at(element.header_line, "too many faces: " + std::to_string(element.count));
        }
      }
    }
    if (!vertex_element_) text_.fail_at(body_, "the header declares no 'vertex' element");
    if (!face_element_ || elements_[*face_element_].count == 0) {
      text_.fail_at(face_element_ ? elements_[*face_element_].header_line : body_,
                    "mesh has no faces (the header declares no face records)",
                    ErrorKind::InvalidInput);
    }
    vertex_count_ = elements_[*vertex_element_].count;
  }

  /// Refuses element counts the bytes after the header cannot hold, before allocating.
  void check_sizes() {
    const std::size_t available = static_cast<std::size_t>(text_.end() - body_);
    std::uint64_t needed = 0;
    for (const Element& element : elements_) {
      std::uint64_t min_record = 0;
      for (const Property& property : element.properties) {
        // Ascii: a token and a separator per value (a list: at least its length).
        min_record += format_ == PlyFormat::Ascii
                          ? 2
                          : scalar_size(property.is_list ? property.count_type : property.type);
      }
      const std::uint64_t slack = format_ == PlyFormat::Ascii ? 1 : 0;
      if (!count_fits(element.count, min_record, available, slack) ||
          needed + element.count * min_record > available + slack) {
        text_.fail_at(element.header_line, "element '" + std::string(element.name) + "' declares " +
                                               std::to_string(element.count) +
                                               " records, but only " + std::to_string(available) +
                                               " bytes follow the header");
      }
      needed += element.count * min_record;
    }
    detail::resize_huge(soup_.positions, static_cast<std::size_t>(vertex_count_));
    const auto faces = static_cast<std::size_t>(elements_[*face_element_].count);
    detail::reserve_huge(soup_.offsets, faces + 1);
    detail::reserve_huge(soup_.vertices, 3 * faces);
  }

  // ---- Ascii body ------------------------------------------------------------------------

  void read_ascii_body() {
    TextScanner in(bytes_, text_.file_name(), {.line_bounded = false, .comment = '\0'});
    in.set_cursor(body_);
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      const Element& element = elements_[e];
      if (element.properties.empty()) continue;  // Nothing to read, however many records.
      for (std::uint64_t record = 0; record < element.count; ++record) {
        for (std::size_t p = 0; p < element.properties.size(); ++p) {
          const Property& property = element.properties[p];
          if (!property.is_list) {
            double value = 0.0;
            read_ascii_value(in, element, record, value);
            if (e == vertex_element_) store_coordinate(record, p, value, in);
            continue;
          }
          double length_value = 0.0;
          read_ascii_value(in, element, record, length_value);
          std::uint64_t length = 0;
          if (!to_index(length_value, std::numeric_limits<std::uint64_t>::max() / 2, length) ||
              !count_fits(length, 2, in.remaining(), 1)) {
            in.fail_at(in.last_token(), "invalid list length " + describe_value(length_value) +
                                            " in record " + std::to_string(record) +
                                            " of element '" + std::string(element.name) + "'");
          }
          const bool is_index_list = e == face_element_ && p == index_property_;
          if (is_index_list)
            check_face_size(length, record, {.text = &in, .position = in.last_token()});
          for (std::uint64_t i = 0; i < length; ++i) {
            double value = 0.0;
            std::int64_t integer = 0;
            if (is_index_list && in.read_integer(integer)) {
              value = static_cast<double>(integer);
            } else {
              read_ascii_value(in, element, record, value);
            }
            if (is_index_list) add_index(value, record, {.text = &in, .position = in.last_token()});
          }
          if (is_index_list) soup_.end_face();
        }
      }
    }
    if (!in.at_end()) {
      in.read_token();
      in.fail_at_token(
          "expected the end of the file after the last element (element counts "
          "do not match the data)");
    }
  }

  void read_ascii_value(TextScanner& in, const Element& element, std::uint64_t record,
                        double& value) {
    if (!in.read_double(value)) {
      in.fail_at_token("expected a number in record " + std::to_string(record) + " of the " +
                       std::to_string(element.count) + " records of element '" +
                       std::string(element.name) + "'");
    }
  }

  void store_coordinate(std::uint64_t record, std::size_t property, double value,
                        const TextScanner& in) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
      if (coordinate_property_[axis] != property) continue;
      if (!std::isfinite(value)) {
        in.fail_at(in.last_token(),
                   "vertex " + std::to_string(record) + " has a non-finite coordinate " +
                       quote_token(in.last_token(), in.end()),
                   ErrorKind::InvalidInput);
      }
      soup_.positions[static_cast<std::size_t>(record)][axis] = value;
    }
  }

  // ---- Binary body -----------------------------------------------------------------------

  void read_binary_body() {
    const BinaryReader in(bytes_, text_.file_name(), format_ == PlyFormat::BinaryBigEndian);
    std::size_t offset = static_cast<std::size_t>(body_ - bytes_.data());
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      const Element& element = elements_[e];
      bool fixed_size = true;
      std::size_t stride = 0;
      for (const Property& property : element.properties) {
        fixed_size = fixed_size && !property.is_list;
        stride += scalar_size(property.type);
      }
      if (fixed_size) {
        // check_sizes() has bounded count * stride by the file size.
        const auto bytes = static_cast<std::size_t>(element.count) * stride;
        if (!in.has(offset, bytes)) {
          const std::size_t complete = (in.size() - offset) / stride;
          in.fail_at(offset + complete * stride,
                     "file ends inside record " + std::to_string(complete) + " of the " +
                         std::to_string(element.count) + " records of element '" +
                         std::string(element.name) + "'");
        }
        if (e == vertex_element_) read_fixed_size_vertices(in, element, offset, stride);
        offset += bytes;
      } else {
        for (std::uint64_t record = 0; record < element.count; ++record) {
          offset = read_binary_record(in, e, record, offset);
        }
      }
    }
    if (offset != in.size()) {
      in.fail_at(offset, std::to_string(in.size() - offset) +
                             " bytes follow the last element (element counts do not match the "
                             "data)");
    }
  }

  void read_fixed_size_vertices(const BinaryReader& in, const Element& element, std::size_t offset,
                                std::size_t stride) {
    std::array<std::size_t, 3> field_offset{};
    std::array<ScalarType, 3> field_type{};
    for (std::size_t axis = 0; axis < 3; ++axis) {
      for (std::size_t p = 0; p < coordinate_property_[axis]; ++p) {
        field_offset[axis] += scalar_size(element.properties[p].type);
      }
      field_type[axis] = element.properties[coordinate_property_[axis]].type;
    }
    const char* data = in.data();
    const bool swap = in.swap();
    for (std::size_t v = 0; v < soup_.positions.size(); ++v, offset += stride) {
      Vec3& position = soup_.positions[v];
      for (std::size_t axis = 0; axis < 3; ++axis) {
        position[axis] = load_as_double(data + offset + field_offset[axis], field_type[axis], swap);
      }
      if (!std::isfinite(position[0]) || !std::isfinite(position[1]) ||
          !std::isfinite(position[2])) {
        in.fail_at(offset, "vertex " + std::to_string(v) + " has a non-finite coordinate",
                   ErrorKind::InvalidInput);
      }
    }
  }

  std::size_t read_binary_record(const BinaryReader& in, std::size_t e, std::uint64_t record,
                                 std::size_t offset) {
    const Element& element = elements_[e];
    const std::size_t record_start = offset;
    const auto truncated = [&] {
      in.fail_at(record_start, "file ends inside record " + std::to_string(record) + " of the " +
                                   std::to_string(element.count) + " records of element '" +
                                   std::string(element.name) + "'");
    };
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const Property& property = element.properties[p];
      if (!property.is_list) {
        if (!in.has(offset, scalar_size(property.type))) truncated();
        if (e == vertex_element_) {
          const double value = in.load(offset, property.type);
          for (std::size_t axis = 0; axis < 3; ++axis) {
            if (coordinate_property_[axis] != p) continue;
            if (!std::isfinite(value)) {
              in.fail_at(record_start,
                         "vertex " + std::to_string(record) + " has a non-finite coordinate",
                         ErrorKind::InvalidInput);
            }
            soup_.positions[static_cast<std::size_t>(record)][axis] = value;
          }
        }
        offset += scalar_size(property.type);
        continue;
      }
      if (!in.has(offset, scalar_size(property.count_type))) truncated();
      const double length_value = in.load(offset, property.count_type);
      const std::size_t item_size = scalar_size(property.type);
      std::uint64_t length = 0;
      if (!to_index(length_value, std::numeric_limits<std::uint32_t>::max() + std::uint64_t{1},
                    length)) {
        in.fail_at(offset, "invalid list length " + describe_value(length_value) + " in record " +
                               std::to_string(record) + " of element '" +
                               std::string(element.name) + "'");
      }
      const std::size_t length_offset = offset;
      offset += scalar_size(property.count_type);
      if (!in.has(offset, static_cast<std::size_t>(length) * item_size)) truncated();
      if (e == face_element_ && p == index_property_) {
        check_face_size(length, record, {.binary = &in, .offset = length_offset});
        for (std::uint64_t i = 0; i < length; ++i, offset += item_size) {
          add_index(in.load(offset, property.type), record, {.binary = &in, .offset = offset});
        }
        soup_.end_face();
      } else {
        offset += static_cast<std::size_t>(length) * item_size;
      }
    }
    return offset;
  }

  // ---- Faces, shared by both bodies --------------------------------------------------------

  void check_face_size(std::uint64_t length, std::uint64_t record, const ErrorSite& site) const {
    if (length < 3) {
      site.fail("face " + std::to_string(record) + " has " + std::to_string(length) +
                " vertices, at least 3 are needed");
    }
  }

  void add_index(double value, std::uint64_t record, const ErrorSite& site) {
    std::uint64_t index = 0;
    if (!to_index(value, vertex_count_, index)) {
      const bool fractional = std::isfinite(value) && value != std::floor(value);
      site.fail("face " + std::to_string(record) + " has vertex index " + describe_value(value) +
                (fractional ? ", not a whole number"
                            : ", outside [0, " + std::to_string(vertex_count_) + ")"));
    }
    soup_.vertices.push_back(static_cast<std::uint32_t>(index));
  }

  static constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();

  std::span<const char> bytes_;
  TextScanner text_;  // The header; also names the file.
  PlyFormat format_ = PlyFormat::Ascii;
  std::vector<Element> elements_;
  const char* body_ = nullptr;
  std::optional<std::size_t> vertex_element_;
  std::optional<std::size_t> face_element_;
  std::array<std::size_t, 3> coordinate_property_{kNone, kNone, kNone};
  std::size_t index_property_ = kNone;
  std::uint64_t vertex_count_ = 0;
  PolygonSoup soup_;
};

}  // namespace

Mesh read_ply(std::span<const char> bytes, std::string_view file_name) {
  return PlyReader(bytes, file_name).read();
}

}  // namespace primseg::mesh_io_detail
