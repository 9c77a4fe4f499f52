// STL reader: ascii and binary detection, welding, and errors.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "mesh_io_test_helpers.hpp"

namespace primseg {
namespace {

using mesh_io_test::Bytes;
using mesh_io_test::expect_error;
using mesh_io_test::parse;
using mesh_io_test::tetrahedron_positions;
using mesh_io_test::tetrahedron_triangles;

Mesh parse_stl(std::string_view bytes) {
  return parse(bytes, MeshFormat::Stl, "part.stl");
}

/// Tetrahedron as a binary STL triangle soup, with the given 80-byte header text.
std::string binary_tetrahedron(std::string_view header_text) {
  Bytes bytes;
  std::string header(header_text);
  header.resize(80, ' ');
  bytes.text(header).put(std::uint32_t{4});
  for (const Triangle& t : tetrahedron_triangles()) {
    for (int i = 0; i < 3; ++i) bytes.put(0.0f);  // Normals are not trusted anyway.
    for (const std::uint32_t v : t) {
      for (const double c : tetrahedron_positions()[v]) bytes.put(static_cast<float>(c));
    }
    bytes.put(std::uint16_t{0});
  }
  return bytes.str();
}

std::string ascii_tetrahedron() {
  std::string text = "solid tetra\n";
  for (const Triangle& t : tetrahedron_triangles()) {
    text += "  facet normal 0 0 0\n    outer loop\n";
    for (const std::uint32_t v : t) {
      const Vec3& p = tetrahedron_positions()[v];
      text += "      vertex " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " +
              std::to_string(p[2]) + "\n";
    }
    text += "    endloop\n  endfacet\n";
  }
  return text + "endsolid tetra\n";
}

/// Welding: the 12 corners become the 4 vertices, numbered by first appearance.
void expect_welded_tetrahedron(const Mesh& mesh) {
  // First appearances in the soup: 0, 2, 1, then 3.
  const std::vector<Vec3> expected_positions{{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}};
  EXPECT_EQ(mesh.positions, expected_positions);
  EXPECT_EQ(mesh.triangles, (std::vector<Triangle>{{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {2, 1, 3}}));
  EXPECT_EQ(mesh.face_count(), 4u);
}

TEST(ReadStl, BinaryIsWeldedDeterministically) {
  expect_welded_tetrahedron(parse_stl(binary_tetrahedron("exported by a CAD tool")));
}

TEST(ReadStl, BinaryWhoseHeaderStartsWithSolid) {
  // Many exporters write "solid <name>" into the binary header; the size gives it away.
  expect_welded_tetrahedron(parse_stl(binary_tetrahedron("solid part")));
  expect_welded_tetrahedron(parse_stl(binary_tetrahedron("solid")));
}

TEST(ReadStl, Ascii) {
  expect_welded_tetrahedron(parse_stl(ascii_tetrahedron()));
  // Upper case keywords, CRLF, and two solids in one file.
  std::string text = ascii_tetrahedron();
  const std::string upper =
      "SOLID A\r\nFACET NORMAL 0 0 1\r\nOUTER LOOP\r\nVERTEX 0 0 0\r\nVERTEX 0 1 0\r\n"
      "VERTEX 1 0 0\r\nENDLOOP\r\nENDFACET\r\nENDSOLID A\r\n";
  const Mesh mesh = parse_stl(upper + text);
  EXPECT_EQ(mesh.face_count(), 5u);
  EXPECT_EQ(mesh.vertex_count(), 4u);
}

TEST(ReadStl, WeldingUsesExactCoordinates) {
  // Two triangles sharing an edge, one corner of which differs by one ulp: not welded; -0 and
  // +0 are equal coordinates: welded.
  const std::string text =
      "solid s\n"
      "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
      "endloop\nendfacet\n"
      "facet normal 0 0 1\nouter loop\nvertex 1.0000000000000002 0 0\nvertex 1 1 0\n"
      "vertex -0 1 -0\nendloop\nendfacet\n"
      "endsolid s\n";
  const Mesh mesh = parse_stl(text);
  EXPECT_EQ(mesh.vertex_count(), 5u);
  EXPECT_EQ(mesh.triangles[1], (Triangle{3, 4, 2}));
}

/// A soup of `triangles` triangles whose corners t, k are at (t, k, 0) and then the first again:
/// a vertex per corner, in order, and the last triangle welded onto the first.
void expect_separate_triangles_then_the_first(const Mesh& mesh, std::uint32_t triangles) {
  ASSERT_EQ(mesh.vertex_count(), 3 * triangles);
  ASSERT_EQ(mesh.face_count(), triangles + 1);
  for (std::uint32_t t = 0; t < triangles; ++t) {
    EXPECT_EQ(mesh.triangles[t], (Triangle{3 * t, 3 * t + 1, 3 * t + 2}));
    for (std::uint32_t k = 0; k < 3; ++k)
      EXPECT_EQ(mesh.positions[3 * t + k], (Vec3{double(t), double(k), 0}));
  }
  EXPECT_EQ(mesh.triangles[triangles], (Triangle{0, 1, 2}));
}

TEST(ReadStl, TightAsciiOutgrowsTheWeldersFirstGuess) {
  // The welder's table is sized from the file's bytes (a corner per 64); a tightly written soup
  // of separate triangles has three new vertices in about 85 bytes, so the table must grow and
  // still find every vertex: the last facet repeats the first one's.
  constexpr std::uint32_t kTriangles = 2000;
  std::string text = "solid s\n";
  auto facet = [&](std::uint32_t t) {
    text += "facet normal 0 0 1 outer loop";
    for (std::uint32_t k = 0; k < 3; ++k)
      text += " vertex " + std::to_string(t) + " " + std::to_string(k) + " 0";
    text += " endloop endfacet\n";
  };
  for (std::uint32_t t = 0; t < kTriangles; ++t) facet(t);
  facet(0);
  text += "endsolid s\n";
  ASSERT_GT(3 * kTriangles, 2 * (text.size() / 64));

  expect_separate_triangles_then_the_first(parse_stl(text), kTriangles);
}

TEST(ReadStl, BinarySoupOutgrowsTheWeldersFirstGuess) {
  // The binary welder's table starts at twice the vertices of a closed mesh (a corner in six); a
  // soup of separate triangles has a vertex per corner, six times more, so the table grows
  // several times and must still find every vertex: the last triangle repeats the first one's.
  constexpr std::uint32_t kTriangles = 5000;
  Bytes bytes;
  bytes.text(std::string(80, ' ')).put(std::uint32_t{kTriangles + 1});
  auto triangle = [&](std::uint32_t t) {
    for (int i = 0; i < 3; ++i) bytes.put(0.0f);
    for (std::uint32_t k = 0; k < 3; ++k) {
      bytes.put(static_cast<float>(t)).put(static_cast<float>(k)).put(0.0f);
    }
    bytes.put(std::uint16_t{0});
  };
  for (std::uint32_t t = 0; t < kTriangles; ++t) triangle(t);
  triangle(0);

  expect_separate_triangles_then_the_first(parse_stl(bytes.str()), kTriangles);
}

TEST(ReadStl, TruncatedBinary) {
  const std::string file = binary_tetrahedron("binary");
  ASSERT_EQ(file.size(), 284u);
  expect_error<ParseError>(
      file.substr(0, 250), MeshFormat::Stl, "part.stl",
      {"part.stl", "byte offset 234", "4 triangles", "250 bytes", "truncated inside triangle 3"});
  // Truncated with a "solid" header: not an ascii file either.
  expect_error<ParseError>(binary_tetrahedron("solid part").substr(0, 200), MeshFormat::Stl,
                           "part.stl", {"part.stl", "byte offset 184", "triangle 2"});
  expect_error<ParseError>(file + "xx", MeshFormat::Stl, "part.stl",
                           {"part.stl", "byte offset 284", "286 bytes"});
}

TEST(ReadStl, BinaryNonFinite) {
  std::string file = binary_tetrahedron("binary");
  const float nan = NAN;
  std::memcpy(file.data() + 84 + 50 + 12 + 12 + 4, &nan, 4);  // Triangle 1, corner 1, y.
  expect_error<InvalidInputError>(
      file, MeshFormat::Stl, "part.stl",
      {"part.stl", "byte offset 158", "corner 1 of triangle 1", "non-finite"});
}

TEST(ReadStl, EmptyAndTooShort) {
  expect_error<ParseError>("", MeshFormat::Stl, "part.stl", {"part.stl", "byte offset 0", "empty"});
  expect_error<ParseError>("hello", MeshFormat::Stl, "part.stl",
                           {"part.stl", "byte offset 0", "'solid'"});
  Bytes empty_binary;
  empty_binary.text(std::string(80, ' ')).put(std::uint32_t{0});
  expect_error<InvalidInputError>(empty_binary.str(), MeshFormat::Stl, "part.stl",
                                  {"part.stl", "byte offset 80", "no faces"});
  expect_error<InvalidInputError>("solid empty\nendsolid empty\n", MeshFormat::Stl, "part.stl",
                                  {"part.stl", "line 3", "no faces"});
}

TEST(ReadStl, AsciiErrors) {
  const std::string head = "solid s\nfacet normal 0 0 1\nouter loop\n";
  expect_error<ParseError>(head + "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n",
                           MeshFormat::Stl, "part.stl",
                           {"part.stl", "line 9", "'endsolid'", "end of file"});
  expect_error<ParseError>(head + "vertex 0 0 0\nvertex 1 0\nvertex 0 1 0\n", MeshFormat::Stl,
                           "part.stl", {"part.stl", "line 6", "coordinate", "'vertex'"});
  expect_error<ParseError>(head + "vertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n",
                           MeshFormat::Stl, "part.stl", {"part.stl", "line 6", "2 vertices"});
  expect_error<ParseError>(head + "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nfacet\n",
                           MeshFormat::Stl, "part.stl", {"part.stl", "line 8", "'endfacet'"});
  expect_error<InvalidInputError>(
      head + "vertex 0 0 0\nvertex 1 0 nan\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n",
      MeshFormat::Stl, "part.stl", {"part.stl", "line 5", "non-finite", "'nan'"});
}

}  // namespace
}  // namespace primseg
