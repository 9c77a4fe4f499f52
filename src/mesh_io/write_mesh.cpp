#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"

#include "file_io.hpp"
#include "huge_pages.hpp"

namespace primseg {
namespace {

using Color = std::array<std::uint8_t, 3>;

/// Output assembled in memory, then written with one system call sequence.
class OutputBuffer {
 public:
  std::string& text() { return text_; }

  OutputBuffer& operator<<(std::string_view s) {
    text_.append(s);
    return *this;
  }
  OutputBuffer& operator<<(char c) {
    text_.push_back(c);
    return *this;
  }
  // Shortest representation that parses back to the same double: round trips are bit-exact.
  OutputBuffer& operator<<(double value) {
    char digits[32];
    const auto result = std::to_chars(digits, digits + sizeof digits, value);
    text_.append(digits, result.ptr);
    return *this;
  }
  OutputBuffer& operator<<(std::uint64_t value) {
    char digits[24];
    const auto result = std::to_chars(digits, digits + sizeof digits, value);
    text_.append(digits, result.ptr);
    return *this;
  }
  OutputBuffer& operator<<(std::uint32_t value) { return *this << std::uint64_t{value}; }

  /// Little-endian binary value.
  template <typename T>
  void put(T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
    text_.append(bytes, sizeof(T));
  }

 private:
  std::string text_;
};

/// Checks the groups and colours of the options against the mesh.
void check_groups(const Mesh& mesh, const MeshWriteOptions& options) {
  if (options.face_groups.empty()) return;
  if (options.face_groups.size() != mesh.face_count()) {
    throw InvalidInputError(
        "write_mesh: face_groups has " + std::to_string(options.face_groups.size()) +
        " entries but the mesh has " + std::to_string(mesh.face_count()) + " faces");
  }
  if (options.group_colors.empty()) return;
  const std::uint32_t largest =
      *std::max_element(options.face_groups.begin(), options.face_groups.end());
  if (options.group_colors.size() <= largest) {
    throw InvalidInputError(
        "write_mesh: group_colors has " + std::to_string(options.group_colors.size()) +
        " colours but face_groups uses groups up to " + std::to_string(largest));
  }
}

/// The colour of each face of checked options (OFF and PLY); empty without groups.
std::vector<Color> face_colors(const MeshWriteOptions& options) {
  if (options.face_groups.empty()) return {};
  if (options.group_colors.empty()) return group_face_colors(options.face_groups);
  std::vector<Color> colors(options.face_groups.size());
  for (std::size_t f = 0; f < colors.size(); ++f)
    colors[f] = options.group_colors[options.face_groups[f]];
  return colors;
}

void write_position(OutputBuffer& out, const Vec3& p) {
  out << p[0] << ' ' << p[1] << ' ' << p[2];
}

// One vertex per line, then one "n v0 .. v(n-1) [r g b]" line per polygon: the body shared by
// OFF and ascii PLY.
void write_ascii_body(OutputBuffer& out, const Mesh& mesh, std::span<const Color> colors) {
  for (const Vec3& p : mesh.positions) {
    write_position(out, p);
    out << '\n';
  }
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
    const auto loop = mesh.polygon(f);
    out << static_cast<std::uint32_t>(loop.size());
    for (const std::uint32_t v : loop) out << ' ' << v;
    if (!colors.empty()) {
      for (const std::uint8_t channel : colors[f]) out << ' ' << std::uint32_t{channel};
    }
    out << '\n';
  }
}

void write_off(OutputBuffer& out, const Mesh& mesh, std::span<const Color> colors) {
  out << "OFF\n" << mesh.vertex_count() << ' ' << mesh.face_count() << " 0\n";
  write_ascii_body(out, mesh, colors);
}

void write_obj(OutputBuffer& out, const Mesh& mesh, std::span<const std::uint32_t> groups) {
  out << "# written by primseg\n";
  for (const Vec3& p : mesh.positions) {
    out << "v ";
    write_position(out, p);
    out << '\n';
  }
  const auto write_face = [&](std::uint32_t f) {
    out << 'f';
    for (const std::uint32_t v : mesh.polygon(f)) out << ' ' << v + 1;
    out << '\n';
  };
  if (groups.empty()) {
    for (std::uint32_t f = 0; f < mesh.face_count(); ++f) write_face(f);
    return;
  }
  // One `g` statement per group: faces sorted by group, in input order within a group.
  std::vector<std::uint32_t> order(mesh.face_count());
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f) order[f] = f;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return groups[a] < groups[b]; });
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (i == 0 || groups[order[i]] != groups[order[i - 1]]) {
      out << "g cluster_" << groups[order[i]] << '\n';
    }
    write_face(order[i]);
  }
}

void write_ply(OutputBuffer& out, const Mesh& mesh, std::span<const Color> colors, bool binary) {
  std::size_t largest_face = 0;
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
    largest_face = std::max(largest_face, mesh.polygon(f).size());
  }
  const bool short_lengths = largest_face <= std::numeric_limits<std::uint8_t>::max();
  const bool signed_indices = mesh.vertex_count() <= std::numeric_limits<std::int32_t>::max();
  out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii")
      << " 1.0\ncomment written by primseg\nelement vertex " << mesh.vertex_count()
      << "\nproperty double x\nproperty double y\nproperty double z\nelement face "
      << mesh.face_count() << "\nproperty list " << (short_lengths ? "uchar " : "uint ")
      << (signed_indices ? "int" : "uint") << " vertex_indices\n";
  if (!colors.empty()) out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out << "end_header\n";

  if (!binary) {
    write_ascii_body(out, mesh, colors);
    return;
  }
  out.text().reserve(out.text().size() + 24 * mesh.positions.size() +
                     4 * mesh.polygon_vertices.size() + 8 * std::size_t{mesh.face_count()});
  for (const Vec3& p : mesh.positions) {
    for (const double c : p) out.put(c);
  }
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
    const auto loop = mesh.polygon(f);
    if (short_lengths) {
      out.put(static_cast<std::uint8_t>(loop.size()));
    } else {
      out.put(static_cast<std::uint32_t>(loop.size()));
    }
    for (const std::uint32_t v : loop) out.put(v);  // int and uint share their bytes here.
    if (!colors.empty()) {
      for (const std::uint8_t channel : colors[f]) out.put(channel);
    }
  }
}

Vec3 unit_normal(const Mesh& mesh, const Triangle& triangle) {
  const Vec3& a = mesh.positions[triangle[0]];
  const Vec3& b = mesh.positions[triangle[1]];
  const Vec3& c = mesh.positions[triangle[2]];
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const Vec3 v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  Vec3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(length > 0.0) || !std::isfinite(length)) return {0.0, 0.0, 0.0};
  for (double& component : n) component /= length;
  return n;
}

void write_stl(OutputBuffer& out, const Mesh& mesh, bool binary) {
  if (!binary) {
    out << "solid primseg\n";
    for (const Triangle& triangle : mesh.triangles) {
      out << "facet normal ";
      write_position(out, unit_normal(mesh, triangle));
      out << "\n outer loop\n";
      for (const std::uint32_t v : triangle) {
        out << "  vertex ";
        write_position(out, mesh.positions[v]);
        out << '\n';
      }
      out << " endloop\nendfacet\n";
    }
    out << "endsolid primseg\n";
    return;
  }
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    for (const double c : mesh.positions[v]) {
      if (std::fabs(c) > std::numeric_limits<float>::max()) {
        throw InvalidInputError("write_mesh: vertex " + std::to_string(v) +
                                " has a coordinate outside the range of binary STL's floats");
      }
    }
  }
  // Must not start with "solid", which would suggest an ascii file to other readers.
  std::string header = "binary STL written by primseg";
  header.resize(80, ' ');
  out << header;
  out.put(mesh.triangle_count());
  out.text().reserve(out.text().size() + 50 * std::size_t{mesh.triangle_count()});
  for (const Triangle& triangle : mesh.triangles) {
    for (const double c : unit_normal(mesh, triangle)) out.put(static_cast<float>(c));
    for (const std::uint32_t v : triangle) {
      for (const double c : mesh.positions[v]) out.put(static_cast<float>(c));
    }
    out.put(std::uint16_t{0});
  }
}

}  // namespace

void write_mesh(const std::filesystem::path& path, const Mesh& mesh,
                const MeshWriteOptions& options) {
  const MeshFormat format = mesh_format_from_path(path);
  mesh.validate();
  check_groups(mesh, options);
  OutputBuffer out;
  // At most what any format takes (text: a shortest round-trip double has at most 24
  // characters, an index 10, a colour channel 3; binary: 24 bytes a vertex, a 4-byte index, a
  // length and a colour; STL 50 bytes a triangle), and the headers, in huge pages: a million
  // faces take tens of MB, whose first touch in 4 KB pages is costly. Pages past what is written
  // are never touched.
  const std::size_t corners = mesh.polygon_vertices.size();
  const std::size_t faces = mesh.face_count();
  detail::reserve_huge(out.text(),
                       std::max(4096 + 80 * mesh.positions.size() + 12 * corners + 32 * faces,
                                84 + 50 * mesh.triangles.size()));
  switch (format) {
    case MeshFormat::Off:
      write_off(out, mesh, face_colors(options));
      break;
    case MeshFormat::Obj:
      write_obj(out, mesh, options.face_groups);
      break;
    case MeshFormat::Ply:
      write_ply(out, mesh, face_colors(options), options.binary);
      break;
    case MeshFormat::Stl:
      write_stl(out, mesh, options.binary);
      break;
  }
  detail::write_file_atomically(path, out.text());
}

std::vector<std::array<std::uint8_t, 3>> distinct_colors(std::size_t count) {
  // Golden-ratio steps spread hues evenly for any count; cycling saturation and value separates
  // the colours that end up with nearby hues.
  constexpr double kGoldenRatioConjugate = 0.6180339887498949;
  constexpr double kSaturations[] = {0.85, 0.55, 0.95, 0.7};
  constexpr double kValues[] = {0.95, 0.8, 0.65};
  std::vector<Color> colors;
  colors.reserve(count);
  double hue = 0.08;
  for (std::size_t i = 0; i < count; ++i) {
    const double saturation = kSaturations[i % 4];
    const double value = kValues[(i / 4) % 3];
    const double sector = hue * 6.0;
    const int index = static_cast<int>(sector) % 6;
    const double fraction = sector - std::floor(sector);
    const double p = value * (1.0 - saturation);
    const double q = value * (1.0 - saturation * fraction);
    const double t = value * (1.0 - saturation * (1.0 - fraction));
    double r = 0, g = 0, b = 0;
    switch (index) {
      case 0:
        r = value, g = t, b = p;
        break;
      case 1:
        r = q, g = value, b = p;
        break;
      case 2:
        r = p, g = value, b = t;
        break;
      case 3:
        r = p, g = q, b = value;
        break;
      case 4:
        r = t, g = p, b = value;
        break;
      default:
        r = value, g = p, b = q;
        break;
    }
    const auto to_byte = [](double channel) {
      return static_cast<std::uint8_t>(std::lround(std::clamp(channel, 0.0, 1.0) * 255.0));
    };
    colors.push_back({to_byte(r), to_byte(g), to_byte(b)});
    hue += kGoldenRatioConjugate;
    hue -= std::floor(hue);
  }
  return colors;
}

std::vector<std::array<std::uint8_t, 3>> group_face_colors(
    std::span<const std::uint32_t> face_groups) {
  if (face_groups.empty()) return {};
  const std::size_t faces = face_groups.size();
  const std::uint32_t largest = *std::max_element(face_groups.begin(), face_groups.end());
  std::vector<Color> colors(faces);
  if (largest < faces) {
    const std::vector<Color> palette = distinct_colors(std::size_t{largest} + 1);
    for (std::size_t f = 0; f < faces; ++f) colors[f] = palette[face_groups[f]];
    return colors;
  }
  // Ids as large as the face count: numbered by rank, so that the palette stays that short.
  std::vector<std::uint32_t> ids(face_groups.begin(), face_groups.end());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  const std::vector<Color> palette = distinct_colors(ids.size());
  for (std::size_t f = 0; f < faces; ++f)
    colors[f] = palette[static_cast<std::size_t>(
        std::lower_bound(ids.begin(), ids.end(), face_groups[f]) - ids.begin())];
  return colors;
}

}  // namespace primseg
