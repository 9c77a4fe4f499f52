#pragma once
// Helpers shared by the mesh I/O tests: parsing in-memory files, checking error messages, and
// assembling binary files byte by byte.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <numbers>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"

namespace primseg::mesh_io_test {

inline Mesh parse(std::string_view bytes, MeshFormat format, std::string_view name = "in-memory") {
  return read_mesh(std::span<const char>(bytes.data(), bytes.size()), format, name);
}

/// Parses `bytes`, expecting exception E whose message contains every one of `fragments`.
/// Returns the message (empty if the expectation failed).
template <typename E>
std::string expect_error(std::string_view bytes, MeshFormat format, std::string_view name,
                         std::initializer_list<std::string_view> fragments) {
  try {
    const Mesh mesh = parse(bytes, format, name);
    ADD_FAILURE() << "no exception; parsed " << mesh.vertex_count() << " vertices and "
                  << mesh.face_count() << " faces";
  } catch (const E& error) {
    const std::string message = error.what();
    for (const std::string_view fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "message \"" << message << "\" lacks \"" << fragment << "\"";
    }
    return message;
  } catch (const std::exception& error) {
    ADD_FAILURE() << "wrong exception type: " << error.what();
  }
  return {};
}

/// One face: the regular n-gon inscribed in the unit circle of the xy plane, counter-clockwise.
inline Mesh regular_polygon(std::uint32_t n) {
  std::vector<Vec3> positions;
  std::vector<std::uint32_t> loop;
  for (std::uint32_t i = 0; i < n; ++i) {
    const double angle = 2 * std::numbers::pi * i / n;
    positions.push_back({std::cos(angle), std::sin(angle), 0.0});
    loop.push_back(i);
  }
  return Mesh::from_polygons(std::move(positions), {0, n}, std::move(loop));
}

/// MeshWriteOptions without designated initializers (which warn about the fields left out).
inline MeshWriteOptions write_options(std::span<const std::uint32_t> groups = {},
                                      std::span<const std::array<std::uint8_t, 3>> colors = {},
                                      bool binary = true) {
  MeshWriteOptions options;
  options.face_groups = groups;
  options.group_colors = colors;
  options.binary = binary;
  return options;
}

/// Binary file image assembled value by value in a chosen byte order.
class Bytes {
 public:
  explicit Bytes(bool big_endian = false) : big_endian_(big_endian) {}

  Bytes& text(std::string_view s) {
    data_.append(s);
    return *this;
  }
  template <typename T>
  Bytes& put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (big_endian_ != (std::endian::native == std::endian::big)) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    }
    data_.append(raw, sizeof(T));
    return *this;
  }
  const std::string& str() const { return data_; }

 private:
  bool big_endian_;
  std::string data_;
};

/// The tetrahedron used throughout: 4 vertices, 4 outward-facing triangles.
inline const std::vector<Vec3>& tetrahedron_positions() {
  static const std::vector<Vec3> positions{
      {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
  return positions;
}
inline const std::vector<Triangle>& tetrahedron_triangles() {
  static const std::vector<Triangle> triangles{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return triangles;
}

inline void expect_tetrahedron(const Mesh& mesh) {
  ASSERT_EQ(mesh.vertex_count(), 4u);
  ASSERT_EQ(mesh.face_count(), 4u);
  ASSERT_EQ(mesh.triangle_count(), 4u);
  EXPECT_EQ(mesh.positions, tetrahedron_positions());
  EXPECT_EQ(mesh.triangles, tetrahedron_triangles());
}

}  // namespace primseg::mesh_io_test
