#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "binary_reader.hpp"
#include "huge_pages.hpp"
#include "readers.hpp"
#include "text_scanner.hpp"

namespace primseg::mesh_io_detail {
namespace {

constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kPreambleBytes = kHeaderBytes + 4;  // Header and triangle count.
constexpr std::size_t kTriangleBytes = 50;  // Normal, 3 corners (12 floats) and attribute word.

/// Merges corners with exactly equal coordinates into one vertex, numbered in order of first
/// appearance. Open addressing over the vertex ids keeps it allocation-free per corner.
class VertexWelder {
 public:
  explicit VertexWelder(std::size_t expected_corners) {
    // A closed mesh has about one vertex per 6 corners; a soup of separate triangles (one per
    // corner) grows the table as it fills. A table sized for the corners would be 12 times
    // larger than needed, and its random probes would miss the caches far more often.
    const std::size_t expected_vertices = expected_corners / 6 + 4;
    std::size_t capacity = 16;
    while (capacity < 2 * expected_vertices) capacity *= 2;
    detail::reserve_huge(slots_, capacity);
    slots_.assign(capacity, kEmpty);
    detail::reserve_huge(positions_, expected_vertices);
  }

  std::uint32_t add(const Vec3& position) {
    // +0.0 folds -0.0 into 0.0, which compares equal to it.
    const Vec3 key{position[0] + 0.0, position[1] + 0.0, position[2] + 0.0};
    if (2 * (positions_.size() + 1) > slots_.size()) grow();
    std::size_t slot = hash(key) & (slots_.size() - 1);
    while (slots_[slot] != kEmpty) {
      const Vec3& existing = positions_[slots_[slot]];
      if (existing[0] == key[0] && existing[1] == key[1] && existing[2] == key[2]) {
        return slots_[slot];
      }
      slot = (slot + 1) & (slots_.size() - 1);
    }
    const auto id = static_cast<std::uint32_t>(positions_.size());
    slots_[slot] = id;
    positions_.push_back(position);
    return id;
  }

  std::vector<Vec3> take_positions() { return std::move(positions_); }

 private:
  static constexpr std::uint32_t kEmpty = 0xffffffffu;

  static std::size_t hash(const Vec3& key) {
    std::uint64_t h = 0x9e3779b97f4a7c15ull;
    for (const double c : key) {
      h ^= std::bit_cast<std::uint64_t>(c);
      h *= 0xff51afd7ed558ccdull;
      h ^= h >> 32;
    }
    return static_cast<std::size_t>(h);
  }

  void grow() {
    std::vector<std::uint32_t> old(slots_.size() * 2, kEmpty);
    old.swap(slots_);
    for (const std::uint32_t id : old) {
      if (id == kEmpty) continue;
      const Vec3& p = positions_[id];
      std::size_t slot = hash({p[0] + 0.0, p[1] + 0.0, p[2] + 0.0}) & (slots_.size() - 1);
      while (slots_[slot] != kEmpty) slot = (slot + 1) & (slots_.size() - 1);
      slots_[slot] = id;
    }
  }

  std::vector<std::uint32_t> slots_;
  std::vector<Vec3> positions_;
};

std::uint32_t declared_triangle_count(std::span<const char> bytes) {
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + kHeaderBytes, sizeof count);
  if constexpr (std::endian::native == std::endian::big) count = byte_swap(count);
  return count;
}

/// Ascii STL starts with "solid" and is text; a binary header may start with "solid" as well, but
/// the triangle count after it nearly always holds a zero byte.
bool looks_like_ascii(std::span<const char> bytes) {
  TextScanner in(bytes, "", {.line_bounded = false, .comment = '\0'});
  const std::string_view first = in.read_token();
  if (first.size() < 5 || !equals_ignoring_case(first.substr(0, 5), "solid")) return false;
  const std::span<const char> start = bytes.first(std::min<std::size_t>(bytes.size(), 512));
  return std::find(start.begin(), start.end(), '\0') == start.end();
}

Mesh read_binary_stl(std::span<const char> bytes, std::string_view file_name) {
  const BinaryReader in(bytes, file_name, /*big_endian=*/false);
  const std::uint32_t count = declared_triangle_count(bytes);
  const std::uint64_t expected = kPreambleBytes + std::uint64_t{kTriangleBytes} * count;
  if (expected != bytes.size()) {
    const bool short_file = expected > bytes.size();
    const std::size_t complete =
        bytes.size() < kPreambleBytes ? 0 : (bytes.size() - kPreambleBytes) / kTriangleBytes;
    in.fail_at(
        short_file ? kPreambleBytes + complete * kTriangleBytes : expected,
        "binary STL declares " + std::to_string(count) + " triangles, which take " +
            std::to_string(expected) + " bytes, but the file has " + std::to_string(bytes.size()) +
            " bytes" +
            (short_file ? " (truncated inside triangle " + std::to_string(complete) + ")" : ""));
  }
  if (count == 0) {
    in.fail_at(kHeaderBytes, "mesh has no faces (the binary STL declares 0 triangles)",
               ErrorKind::InvalidInput);
  }
  VertexWelder welder(3 * std::size_t{count});
  std::vector<Triangle> triangles;
  detail::resize_huge(triangles, count);
  const char* data = bytes.data();
  for (std::uint32_t t = 0; t < count; ++t) {
    const std::size_t corners = kPreambleBytes + std::size_t{t} * kTriangleBytes + 12;
    for (std::size_t corner = 0; corner < 3; ++corner) {
      Vec3 position;
      for (std::size_t axis = 0; axis < 3; ++axis) {
        position[axis] =
            load_as_double(data + corners + 12 * corner + 4 * axis, ScalarType::Float32, in.swap());
      }
      if (!std::isfinite(position[0]) || !std::isfinite(position[1]) ||
          !std::isfinite(position[2])) {
        in.fail_at(corners + 12 * corner,
                   "corner " + std::to_string(corner) + " of triangle " + std::to_string(t) +
                       " has a non-finite coordinate",
                   ErrorKind::InvalidInput);
      }
      triangles[t][corner] = welder.add(position);
    }
  }
  return Mesh::from_triangles(welder.take_positions(), std::move(triangles));
}

class AsciiStlReader {
 public:
  AsciiStlReader(std::span<const char> bytes, std::string_view file_name)
      : in_(bytes, file_name, {.line_bounded = false, .comment = '\0'}),
        welder_(bytes.size() / 64) {}

  Mesh read() {
    // One file may hold several solids one after the other.
    do {
      expect("solid");
      in_.skip_line();  // The solid's name.
      read_facets();
    } while (!in_.at_end());
    if (soup_.face_count() == 0) {
      in_.fail_at(in_.end(), "mesh has no faces (the STL file has no facets)",
                  ErrorKind::InvalidInput);
    }
    soup_.positions = welder_.take_positions();
    return to_mesh(std::move(soup_));
  }

 private:
  void expect(std::string_view keyword) {
    if (!equals_ignoring_case(in_.read_token(), keyword)) {
      in_.fail_at_token("expected '" + std::string(keyword) + "'");
    }
  }

  void read_facets() {
    while (true) {
      const std::string_view keyword = in_.read_token();
      if (equals_ignoring_case(keyword, "endsolid")) {
        in_.skip_line();
        return;
      }
      if (!equals_ignoring_case(keyword, "facet")) {
        in_.fail_at_token("expected 'facet' or 'endsolid'");
      }
      // The normal is recomputed from the corners whenever it is needed: skip it.
      expect("normal");
      for (int axis = 0; axis < 3; ++axis) read_number("a normal component");
      expect("outer");
      expect("loop");
      const std::size_t first = soup_.vertices.size();
      while (true) {
        const std::string_view word = in_.read_token();
        if (equals_ignoring_case(word, "endloop")) break;
        if (!equals_ignoring_case(word, "vertex"))
          in_.fail_at_token("expected 'vertex' or 'endloop'");
        Vec3 position;
        for (double& coordinate : position) {
          coordinate = read_number("a vertex coordinate");
          if (!std::isfinite(coordinate)) {
            in_.fail_at(
                in_.last_token(),
                "vertex has a non-finite coordinate " + quote_token(in_.last_token(), in_.end()),
                ErrorKind::InvalidInput);
          }
        }
        soup_.vertices.push_back(welder_.add(position));
      }
      const std::size_t size = soup_.vertices.size() - first;
      if (size < 3) {
        in_.fail_at(in_.last_token(),
                    "facet has " + std::to_string(size) + " vertices, at least 3 are needed");
      }
      soup_.end_face();
      expect("endfacet");
    }
  }

  double read_number(const char* what) {
    double value = 0.0;
    if (!in_.read_double(value)) in_.fail_at_token(std::string("expected ") + what);
    return value;
  }

  TextScanner in_;
  VertexWelder welder_;
  PolygonSoup soup_;
};

}  // namespace

Mesh read_stl(std::span<const char> bytes, std::string_view file_name) {
  if (bytes.empty()) raise(ErrorKind::Parse, file_name, offset_location(0), "file is empty");
  // A binary file may start with "solid" too; its size, which must match the triangle count
  // exactly, is the reliable tell.
  if (bytes.size() >= kPreambleBytes &&
      bytes.size() ==
          kPreambleBytes + std::uint64_t{kTriangleBytes} * declared_triangle_count(bytes)) {
    return read_binary_stl(bytes, file_name);
  }
  if (looks_like_ascii(bytes)) return AsciiStlReader(bytes, file_name).read();
  if (bytes.size() < kPreambleBytes) {
    raise(ErrorKind::Parse, file_name, offset_location(0),
          "not an STL file: too short for a binary STL (" + std::to_string(bytes.size()) +
              " bytes, the header alone takes 84) and it does not start with 'solid'");
  }
  return read_binary_stl(bytes, file_name);  // Reports the size mismatch.
}

}  // namespace primseg::mesh_io_detail
