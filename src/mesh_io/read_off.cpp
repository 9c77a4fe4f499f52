#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "huge_pages.hpp"
#include "readers.hpp"
#include "text_scanner.hpp"

namespace primseg::mesh_io_detail {
namespace {

constexpr std::int64_t kMaxCount = std::numeric_limits<std::uint32_t>::max();
// Smallest text a vertex ("0 0 0\n") and a face ("3 0 0 0\n") can take: the bound that stops a
// forged header count before anything is allocated for it.
constexpr std::uint64_t kMinVertexBytes = 6;
constexpr std::uint64_t kMinFaceBytes = 8;

/// "OFF" with the optional prefixes of the Geomview family: ST (texture), C (colour), N (normal),
/// 4 (homogeneous), n (dimension follows). Per-vertex extras are skipped as the rest of the line.
bool is_off_keyword(std::string_view token, bool& dimension_follows) {
  if (token.size() < 3 || token.substr(token.size() - 3) != "OFF") return false;
  std::string_view prefix = token.substr(0, token.size() - 3);
  if (prefix.starts_with("ST")) prefix.remove_prefix(2);
  for (const char flag : {'C', 'N', '4', 'n'}) {
    if (!prefix.empty() && prefix.front() == flag) prefix.remove_prefix(1);
  }
  dimension_follows = token.size() >= 4 && token[token.size() - 4] == 'n';
  return prefix.empty();
}

std::int64_t read_count(TextScanner& in, const char* what) {
  std::int64_t count = 0;
  if (!in.read_integer(count)) in.fail_at_token(std::string("expected the ") + what);
  if (count < 0 || count > kMaxCount) {
    in.fail_at(in.last_token(), std::string("invalid ") + what + " " + std::to_string(count));
  }
  return count;
}

// The counts of the header ("OFF", or an old file's bare counts), the cursor after its line; the
// counts checked against what the file can hold.
struct OffCounts {
  std::int64_t vertices = 0, faces = 0;
};

OffCounts read_off_header(TextScanner& in) {
  const char* header = in.cursor();
  bool dimension_follows = false;
  if (is_off_keyword(in.read_token(), dimension_follows)) {
    if (dimension_follows) {
      std::int64_t dimension = 0;
      if (!in.read_integer(dimension)) in.fail_at_token("expected the dimension after 'nOFF'");
      if (dimension != 3) {
        in.fail_at(in.last_token(), "only 3-dimensional OFF files are supported, this one has " +
                                        std::to_string(dimension) + " dimensions");
      }
    }
    std::string_view next = in.read_token();
    if (next == "BINARY") in.fail_at(in.last_token(), "binary OFF files are not supported");
    in.set_cursor(in.last_token());
  } else {
    in.set_cursor(header);  // Old files omit the keyword and start with the counts.
  }
  const char* counts = in.cursor();
  const std::int64_t vertex_count = read_count(in, "vertex count");
  const std::int64_t face_count = read_count(in, "face count");
  if (in.token_follows_on_line()) read_count(in, "edge count");  // Unused, often absent.
  in.skip_line();

  const auto declared = static_cast<std::uint64_t>(vertex_count) * kMinVertexBytes +
                        static_cast<std::uint64_t>(face_count) * kMinFaceBytes;
  if (declared > in.remaining() + 1) {
    in.fail_at(counts, "header declares " + std::to_string(vertex_count) + " vertices and " +
                           std::to_string(face_count) + " faces, which need at least " +
                           std::to_string(declared) + " bytes, but only " +
                           std::to_string(in.remaining()) + " bytes follow");
  }
  if (face_count == 0) {
    in.fail_at(counts, "mesh has no faces (the header declares 0 faces)", ErrorKind::InvalidInput);
  }
  return {vertex_count, face_count};
}

void read_off_vertices(TextScanner& in, std::int64_t vertex_count, std::vector<Vec3>& positions) {
  detail::resize_huge(positions, static_cast<std::size_t>(vertex_count));
  for (std::int64_t v = 0; v < vertex_count; ++v) {
    Vec3& position = positions[static_cast<std::size_t>(v)];
    for (double& coordinate : position) {
      if (!in.read_double(coordinate)) {
        in.fail_at_token("expected a coordinate of vertex " + std::to_string(v) + " of the " +
                         std::to_string(vertex_count) + " the header declares");
      }
      if (!std::isfinite(coordinate)) {
        in.fail_at(in.last_token(),
                   "vertex " + std::to_string(v) + " has a non-finite coordinate " +
                       quote_token(in.last_token(), in.end()),
                   ErrorKind::InvalidInput);
      }
    }
    in.skip_line();  // Colour, normal or texture values of COFF/NOFF/STOFF.
  }
}

void read_off_faces(TextScanner& in, const OffCounts& counts, PolygonSoup& soup) {
  detail::reserve_huge(soup.offsets, static_cast<std::size_t>(counts.faces) + 1);
  detail::reserve_huge(soup.vertices, 3 * static_cast<std::size_t>(counts.faces));
  const auto vertex_limit = static_cast<std::uint64_t>(counts.vertices);
  for (std::int64_t f = 0; f < counts.faces; ++f) {
    std::int64_t size = 0;
    if (!in.read_integer(size)) {
      in.fail_at_token("expected the vertex count of face " + std::to_string(f) + " of the " +
                       std::to_string(counts.faces) + " the header declares");
    }
    if (size < 3) {
      in.fail_at(in.last_token(), "face " + std::to_string(f) + " has " + std::to_string(size) +
                                      " vertices, at least 3 are needed");
    }
    if (!count_fits(static_cast<std::uint64_t>(size), 2, in.remaining(), 1)) {
      in.fail_at(in.last_token(), "face " + std::to_string(f) + " declares " +
                                      std::to_string(size) + " vertices but only " +
                                      std::to_string(in.remaining()) + " bytes follow");
    }
    for (std::int64_t corner = 0; corner < size; ++corner) {
      std::int64_t index = 0;
      if (!in.read_integer(index)) {
        in.fail_at_token("expected vertex index " + std::to_string(corner) + " of face " +
                         std::to_string(f));
      }
      if (index < 0 || static_cast<std::uint64_t>(index) >= vertex_limit) {
        in.fail_at(in.last_token(), "face " + std::to_string(f) + " has vertex index " +
                                        std::to_string(index) + ", outside [0, " +
                                        std::to_string(counts.vertices) + ")");
      }
      soup.vertices.push_back(static_cast<std::uint32_t>(index));
    }
    soup.end_face();
    in.skip_line();  // Per-face colour.
  }
}

}  // namespace

Mesh read_off(std::span<const char> bytes, std::string_view file_name) {
  TextScanner in(bytes, file_name, {.line_bounded = false, .comment = '#'});
  if (in.at_end()) in.fail_at(in.cursor(), "file is empty");
  const OffCounts counts = read_off_header(in);
  PolygonSoup soup;
  read_off_vertices(in, counts.vertices, soup.positions);
  read_off_faces(in, counts, soup);
  if (!in.at_end()) {
    in.read_token();
    in.fail_at_token("expected the end of the file after the " + std::to_string(counts.vertices) +
                     " vertices and " + std::to_string(counts.faces) +
                     " faces the header declares");
  }
  return to_mesh(std::move(soup));
}

}  // namespace primseg::mesh_io_detail
