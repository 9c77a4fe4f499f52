// write_mesh: bit-exact round trips in every format, groups and colours, atomic replacement.

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <set>
#include <string>

#include "mesh_io_test_helpers.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using mesh_io_test::write_options;

/// Coordinates chosen to break any printing that is not shortest-round-trip: thirds, tenths,
/// extremes, a subnormal, negative zero.
Mesh awkward_mesh() {
  std::vector<Vec3> positions{
      {0.1, 1.0 / 3.0, -2.0 / 7.0},
      {1e-300, 1e300, std::numbers::pi},
      {5e-324, -0.0, 123456789.123456789},
      {-1.7976931348623157e308, 2.2250738585072014e-308, 0.30000000000000004},
      {std::nextafter(1.0, 2.0), std::nextafter(1.0, 0.0), -1e-7},
      {42.0, -42.0, 1e22},
      {7.0, 8.0, 9.0},  // Isolated.
  };
  // A triangle, a quad and a pentagon (non-planar, non-convex: whatever the triangulation).
  return Mesh::from_polygons(positions, {0, 3, 7, 12}, {0, 1, 2, 2, 1, 3, 4, 0, 2, 4, 5, 3});
}

void expect_bitwise_equal(const Vec3& a, const Vec3& b) {
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a[axis]), std::bit_cast<std::uint64_t>(b[axis]))
        << a[axis] << " became " << b[axis];
  }
}

void expect_same_polygon_mesh(const Mesh& written, const Mesh& read) {
  ASSERT_EQ(read.vertex_count(), written.vertex_count());
  for (std::uint32_t v = 0; v < written.vertex_count(); ++v) {
    expect_bitwise_equal(written.positions[v], read.positions[v]);
  }
  EXPECT_EQ(read.polygon_offsets, written.polygon_offsets);
  EXPECT_EQ(read.polygon_vertices, written.polygon_vertices);
  EXPECT_EQ(read.triangles, written.triangles);
  EXPECT_EQ(read.face_of_triangle, written.face_of_triangle);
}

/// STL keeps triangles only and welds: compare the corners of each triangle.
void expect_same_triangle_soup(const Mesh& written, const Mesh& read) {
  ASSERT_EQ(read.triangle_count(), written.triangle_count());
  for (std::uint32_t t = 0; t < written.triangle_count(); ++t) {
    for (int corner = 0; corner < 3; ++corner) {
      expect_bitwise_equal(written.positions[written.triangles[t][corner]],
                           read.positions[read.triangles[t][corner]]);
    }
  }
}

class WriteMeshTest : public ::testing::Test {
 protected:
  std::filesystem::path directory_ = testing::temp_directory("mesh_io_write");
  void TearDown() override { std::filesystem::remove_all(directory_); }
};

TEST_F(WriteMeshTest, PolygonFormatsRoundTripBitExact) {
  const Mesh mesh = awkward_mesh();
  for (const char* name : {"m.off", "m.obj", "m.ply"}) {
    for (const bool binary : {true, false}) {
      SCOPED_TRACE(std::string(name) + (binary ? " binary" : " ascii"));
      const std::filesystem::path path = directory_ / name;
      write_mesh(path, mesh, write_options({}, {}, binary));
      expect_same_polygon_mesh(mesh, read_mesh(path));
    }
  }
}

TEST_F(WriteMeshTest, StlRoundTrips) {
  // Ascii: doubles survive exactly.
  const Mesh mesh = awkward_mesh();
  write_mesh(directory_ / "m.stl", mesh, write_options({}, {}, false));
  expect_same_triangle_soup(mesh, read_mesh(directory_ / "m.stl"));

  // Binary stores floats: exact for float-representable coordinates.
  std::vector<Vec3> positions;
  for (const Vec3& p : mesh.positions) {
    Vec3 q;
    for (int axis = 0; axis < 3; ++axis) {
      q[axis] = static_cast<float>(std::clamp(p[axis], -1e38, 1e38));
    }
    positions.push_back(q);
  }
  const Mesh floats = Mesh::from_polygons(positions, mesh.polygon_offsets, mesh.polygon_vertices);
  write_mesh(directory_ / "f.stl", floats);
  const std::string bytes = testing::file_contents(directory_ / "f.stl");
  ASSERT_EQ(bytes.size(), 84u + 50u * floats.triangle_count());
  EXPECT_NE(bytes.substr(0, 5), "solid");
  expect_same_triangle_soup(floats, read_mesh(directory_ / "f.stl"));

  // Out of float range: refused rather than written as inf.
  EXPECT_THROW(write_mesh(directory_ / "m.stl", mesh), InvalidInputError);
}

TEST_F(WriteMeshTest, StlNormalsAreUnitOrZeroForADegenerateTriangle) {
  // A right triangle in z = 0 and a degenerate one (three collinear points): the first's normal
  // is +z, the second's has no direction and is written as zeros, never as NaN.
  const Mesh mesh = Mesh::from_triangles(
      {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}, {{0, 1, 2}, {3, 4, 5}});
  write_mesh(directory_ / "a.stl", mesh, write_options({}, {}, false));
  const std::string text = testing::file_contents(directory_ / "a.stl");
  EXPECT_NE(text.find("facet normal 0 0 1\n"), std::string::npos) << text;
  EXPECT_NE(text.find("facet normal 0 0 0\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("nan"), std::string::npos) << text;

  write_mesh(directory_ / "b.stl", mesh);
  const std::string bytes = testing::file_contents(directory_ / "b.stl");
  ASSERT_EQ(bytes.size(), 84u + 2 * 50u);
  auto normal_component = [&](int triangle, int axis) {
    float value;
    std::memcpy(&value, bytes.data() + 84 + 50 * triangle + 4 * axis, 4);
    return value;
  };
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(normal_component(0, axis), axis == 2 ? 1.0f : 0.0f);
    EXPECT_EQ(normal_component(1, axis), 0.0f);
  }
}

TEST_F(WriteMeshTest, PlyListLengthsAreBytesUpTo255Vertices) {
  // uchar lengths, what most PLY readers expect, whenever every face fits; uint beyond.
  for (const std::uint32_t n : {255u, 256u}) {
    const Mesh mesh = mesh_io_test::regular_polygon(n);
    for (const bool binary : {true, false}) {
      SCOPED_TRACE(std::to_string(n) + (binary ? " binary" : " ascii"));
      write_mesh(directory_ / "p.ply", mesh, write_options({}, {}, binary));
      const std::string text = testing::file_contents(directory_ / "p.ply");
      const std::string expected = n <= 255 ? "property list uchar int vertex_indices\n"
                                            : "property list uint int vertex_indices\n";
      EXPECT_NE(text.find(expected), std::string::npos) << text.substr(0, 300);
      expect_same_polygon_mesh(mesh, read_mesh(directory_ / "p.ply"));
    }
  }
}

TEST_F(WriteMeshTest, PlyFaceColoursFromGroups) {
  const Mesh mesh = awkward_mesh();
  const std::vector<std::uint32_t> groups{2, 0, 2};
  const std::vector<std::array<std::uint8_t, 3>> colors{{1, 2, 3}, {4, 5, 6}, {7, 8, 9}};
  const std::filesystem::path path = directory_ / "c.ply";
  write_mesh(path, mesh, write_options(groups, colors));
  const std::string bytes = testing::file_contents(path);
  const std::string header_end = "end_header\n";
  const std::size_t body = bytes.find(header_end) + header_end.size();
  EXPECT_NE(bytes.substr(0, body).find("property uchar red\nproperty uchar green\n"
                                       "property uchar blue\n"),
            std::string::npos);
  // Faces: uchar length, int indices, rgb.
  std::size_t offset = body + 24 * mesh.vertex_count();
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
    const auto length = static_cast<std::uint8_t>(bytes[offset]);
    ASSERT_EQ(length, mesh.polygon(f).size());
    offset += 1 + 4 * std::size_t{length};
    for (int channel = 0; channel < 3; ++channel) {
      EXPECT_EQ(static_cast<std::uint8_t>(bytes[offset + channel]), colors[groups[f]][channel]);
    }
    offset += 3;
  }
  EXPECT_EQ(offset, bytes.size());
  expect_same_polygon_mesh(mesh, read_mesh(path));

  write_mesh(directory_ / "a.ply", mesh, write_options(groups, {}, false));
  expect_same_polygon_mesh(mesh, read_mesh(directory_ / "a.ply"));
  const auto palette = distinct_colors(3);
  const std::string text = testing::file_contents(directory_ / "a.ply");
  const std::string last_face = "5 0 2 4 5 3 " + std::to_string(palette[2][0]) + " " +
                                std::to_string(palette[2][1]) + " " +
                                std::to_string(palette[2][2]) + "\n";
  EXPECT_TRUE(text.ends_with(last_face)) << text;
}

TEST_F(WriteMeshTest, ObjGroupsAndOffColours) {
  const Mesh mesh = awkward_mesh();
  const std::vector<std::uint32_t> groups{5, 1, 5};
  write_mesh(directory_ / "g.obj", mesh, write_options(groups));
  const std::string obj = testing::file_contents(directory_ / "g.obj");
  const std::size_t group_1 =
      obj.find("g cluster_1\nf 3 2 4 5\ng cluster_5\nf 1 2 3\nf 1 3 5 6 4\n");
  EXPECT_NE(group_1, std::string::npos) << obj;
  EXPECT_EQ(read_mesh(directory_ / "g.obj").face_count(), 3u);

  const std::vector<std::array<std::uint8_t, 3>> colors(6, {10, 20, 30});
  write_mesh(directory_ / "c.off", mesh, write_options(groups, colors));
  const std::string off = testing::file_contents(directory_ / "c.off");
  EXPECT_TRUE(off.ends_with("3 0 1 2 10 20 30\n4 2 1 3 4 10 20 30\n5 0 2 4 5 3 10 20 30\n")) << off;
  expect_same_polygon_mesh(mesh, read_mesh(directory_ / "c.off"));
}

TEST_F(WriteMeshTest, GroupIdsBeyondTheFaceCountAreColouredByRank) {
  const Mesh mesh = awkward_mesh();
  // Ids below the face count keep their colour whatever else occurs; larger ones are ranked (a
  // palette of four billion colours would not fit in memory).
  const std::vector<std::uint32_t> sparse{4000000000u, 7, 4000000000u};
  const std::vector<std::uint32_t> ranked{1, 0, 1};
  for (const bool binary : {true, false}) {
    write_mesh(directory_ / "sparse.ply", mesh, write_options(sparse, {}, binary));
    write_mesh(directory_ / "ranked.ply", mesh, write_options(ranked, {}, binary));
    EXPECT_EQ(testing::file_contents(directory_ / "sparse.ply"),
              testing::file_contents(directory_ / "ranked.ply"));
  }
  write_mesh(directory_ / "sparse.off", mesh, write_options(sparse));
  write_mesh(directory_ / "ranked.off", mesh, write_options(ranked));
  EXPECT_EQ(testing::file_contents(directory_ / "sparse.off"),
            testing::file_contents(directory_ / "ranked.off"));
  write_mesh(directory_ / "sparse.obj", mesh, write_options(sparse));  // groups keep their ids
  EXPECT_NE(testing::file_contents(directory_ / "sparse.obj").find("g cluster_4000000000\n"),
            std::string::npos);
}

TEST_F(WriteMeshTest, RejectsBadOptionsAndPaths) {
  const Mesh mesh = awkward_mesh();
  const std::vector<std::uint32_t> too_few{0, 1};
  EXPECT_THROW(write_mesh(directory_ / "x.ply", mesh, write_options(too_few)), InvalidInputError);
  const std::vector<std::uint32_t> groups{0, 3, 1};
  const std::vector<std::array<std::uint8_t, 3>> colors(3, {0, 0, 0});
  EXPECT_THROW(write_mesh(directory_ / "x.ply", mesh, write_options(groups, colors)),
               InvalidInputError);
  EXPECT_THROW(write_mesh(directory_ / "x.vrml", mesh), InvalidInputError);
  EXPECT_THROW(write_mesh(directory_ / "missing" / "x.ply", mesh), IoError);
  Mesh broken = mesh;
  broken.positions[0][0] = NAN;
  EXPECT_THROW(write_mesh(directory_ / "x.ply", broken), InvalidInputError);
  EXPECT_FALSE(std::filesystem::exists(directory_ / "x.ply"));
}

TEST_F(WriteMeshTest, ReplacesAtomicallyAndLeavesNoTemporaryFiles) {
  const Mesh mesh = awkward_mesh();
  const std::filesystem::path path = directory_ / "m.ply";
  {
    std::ofstream old(path);
    old << "old contents";
  }
  write_mesh(path, mesh);
  expect_same_polygon_mesh(mesh, read_mesh(path));
  std::size_t entries = 0;
  for (const auto& entry : std::filesystem::directory_iterator(directory_)) {
    ++entries;
    EXPECT_EQ(entry.path().filename(), "m.ply");
  }
  EXPECT_EQ(entries, 1u);
}

TEST_F(WriteMeshTest, ReadErrorsOfPaths) {
  EXPECT_THROW(read_mesh(directory_ / "none.off"), IoError);
  EXPECT_THROW(read_mesh(directory_), InvalidInputError);  // No known extension.
  std::filesystem::create_directory(directory_ / "dir.off");
  EXPECT_THROW(read_mesh(directory_ / "dir.off"), IoError);
  try {
    read_mesh(directory_ / "mesh.3ds");
    FAIL();
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("mesh.3ds"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("'.3ds'"), std::string::npos);
  }
  // Extensions are case-insensitive; the path appears in parse errors.
  {
    std::ofstream file(directory_ / "UPPER.OFF");
    file << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n";
  }
  try {
    read_mesh(directory_ / "UPPER.OFF");
    FAIL();
  } catch (const ParseError& error) {
    EXPECT_NE(std::string(error.what()).find((directory_ / "UPPER.OFF").string() + ": line 6"),
              std::string::npos)
        << error.what();
  }
  EXPECT_EQ(mesh_format_from_path("a/b.Ply"), MeshFormat::Ply);
  EXPECT_EQ(mesh_format_from_path("b.stl"), MeshFormat::Stl);
  EXPECT_EQ(mesh_format_from_path("b.obj"), MeshFormat::Obj);
}

TEST(GroupFaceColors, GroupKGetsColourKAndLargeIdsTheirRank) {
  const auto palette = distinct_colors(3);
  const std::vector<std::uint32_t> dense{2, 0, 2};
  EXPECT_EQ(group_face_colors(dense),
            (std::vector<std::array<std::uint8_t, 3>>{palette[2], palette[0], palette[2]}));
  const std::vector<std::uint32_t> sparse{4000000000u, 7, 4000000000u};  // 7 >= F = 3
  EXPECT_EQ(group_face_colors(sparse),
            (std::vector<std::array<std::uint8_t, 3>>{palette[1], palette[0], palette[1]}));
  EXPECT_TRUE(group_face_colors({}).empty());
}

TEST(DistinctColors, DeterministicAndWellSeparated) {
  const auto colors = distinct_colors(64);
  ASSERT_EQ(colors.size(), 64u);
  EXPECT_EQ(colors, distinct_colors(64));
  EXPECT_TRUE(distinct_colors(0).empty());
  const auto distance = [](const std::array<std::uint8_t, 3>& a,
                           const std::array<std::uint8_t, 3>& b) {
    double sum = 0;
    for (int i = 0; i < 3; ++i) {
      const double d = static_cast<double>(a[i]) - static_cast<double>(b[i]);
      sum += d * d;
    }
    return std::sqrt(sum);
  };
  for (std::size_t i = 1; i < colors.size(); ++i) {
    EXPECT_GT(distance(colors[i], colors[i - 1]), 60.0) << i;
  }
  // The first dozen, the usual cluster counts, are pairwise distinguishable.
  for (std::size_t i = 0; i < 12; ++i) {
    for (std::size_t j = 0; j < i; ++j) EXPECT_GT(distance(colors[i], colors[j]), 25.0) << i << j;
  }
  const std::set<std::array<std::uint8_t, 3>> unique(colors.begin(), colors.end());
  EXPECT_EQ(unique.size(), colors.size());
}

}  // namespace
}  // namespace primseg
