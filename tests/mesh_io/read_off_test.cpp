// OFF reader: variants real files use, and the errors users get for broken ones.

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "mesh_io_test_helpers.hpp"

namespace primseg {
namespace {

using mesh_io_test::expect_error;
using mesh_io_test::expect_tetrahedron;
using mesh_io_test::parse;

constexpr std::string_view kTetrahedron =
    "OFF\n"
    "# a tetrahedron\n"
    "4 4 6\n"
    "0 0 0\n"
    "1 0 0\n"
    "0 1 0\n"
    "0 0 1\n"
    "3 0 2 1\n"
    "3 0 1 3\n"
    "3 0 3 2\n"
    "3 1 2 3\n";

Mesh parse_off(std::string_view text) {
  return parse(text, MeshFormat::Off, "shape.off");
}

TEST(ReadOff, Tetrahedron) {
  expect_tetrahedron(parse_off(kTetrahedron));
}

TEST(ReadOff, LayoutVariants) {
  // Counts on the keyword line, no edge count, comments and blank lines anywhere, CRLF, tabs,
  // no final newline.
  expect_tetrahedron(
      parse_off("OFF 4 4\r\n\r\n# vertices\r\n0 0 0\r\n1\t0 0 # trailing comment\r\n0 1 0\r\n"
                "0 0 1\r\n\r\n3 0 2 1\r\n3 0 1 3\r\n# faces continue\r\n3 0 3 2\r\n3 1 2 3"));
  // Old files without the keyword.
  expect_tetrahedron(parse_off(std::string(kTetrahedron.substr(4))));
  // Explicit signs and exponents.
  const Mesh mesh = parse_off("OFF\n3 1 0\n+1.5e0 -2.25E+1 .5\n1e-3 0 -0\n1 1 1\n3 0 1 2\n");
  EXPECT_EQ(mesh.positions[0], (Vec3{1.5, -22.5, 0.5}));
  EXPECT_EQ(mesh.positions[1], (Vec3{0.001, 0.0, 0.0}));
}

TEST(ReadOff, ColourAndNormalVariantsIgnoreTheExtras) {
  expect_tetrahedron(parse_off(
      "COFF\n4 4 6\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n"
      "0 0 1 0.5 0.5 0.5 1\n3 0 2 1 255 0 0\n3 0 1 3 0 255 0\n3 0 3 2 0 0 255\n3 1 2 3\n"));
  expect_tetrahedron(
      parse_off("NOFF\n4 4 6\n0 0 0 -1 -1 -1\n1 0 0 1 0 0\n0 1 0 0 1 0\n0 0 1 0 0 1\n"
                "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"));
  expect_tetrahedron(
      parse_off("CNOFF\n4 4 6\n0 0 0 -1 -1 -1 1 1 1 1\n1 0 0 1 0 0 1 1 1 1\n0 1 0 0 1 0 1 1 1 1\n"
                "0 0 1 0 0 1 1 1 1 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"));
}

TEST(ReadOff, PolygonsAreTriangulated) {
  // A cube of 6 quads.
  const Mesh mesh = parse_off(
      "OFF\n8 6 12\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
      "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n");
  EXPECT_EQ(mesh.face_count(), 6u);
  EXPECT_EQ(mesh.triangle_count(), 12u);
  EXPECT_EQ(mesh.face_of_triangle,
            (std::vector<std::uint32_t>{0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5}));
  EXPECT_EQ(mesh.polygon(1).size(), 4u);
  EXPECT_EQ(mesh.polygon(1)[2], 6u);
}

TEST(ReadOff, EmptyFile) {
  expect_error<ParseError>("", MeshFormat::Off, "shape.off", {"shape.off", "line 1", "empty"});
  expect_error<ParseError>("# only a comment\n\n", MeshFormat::Off, "shape.off",
                           {"shape.off", "empty"});
}

TEST(ReadOff, FewerVerticesThanDeclared) {
  // 3 of the 4 declared vertices: the faces are read as vertices until the file runs out.
  expect_error<ParseError>("OFF\n4 2 0\n0.0 0.0 0.0\n1.0 0.0 0.0\n0.0 1.0 0.0\n3 0 1 2\n3 0 2 1\n",
                           MeshFormat::Off, "shape.off",
                           {"shape.off", "line 8", "face 1 of the 2", "end of file"});
}

TEST(ReadOff, FewerFacesThanDeclared) {
  expect_error<ParseError>("OFF\n3 3 0\n0.0 0.0 0.0\n1.0 0.0 0.0\n0.0 1.0 0.0\n3 0 1 2\n3 0 2 1\n",
                           MeshFormat::Off, "shape.off",
                           {"shape.off", "line 8", "face 2 of the 3", "end of file"});
}

TEST(ReadOff, MoreDataThanDeclared) {
  expect_error<ParseError>("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n", MeshFormat::Off,
                           "shape.off", {"shape.off", "line 7", "end of the file", "'3'"});
}

TEST(ReadOff, TruncatedInsideAFace) {
  expect_error<ParseError>("OFF\n3 1 0\n0.0 0.0 0.0\n1 0 0\n0 1 0\n3 0 1", MeshFormat::Off,
                           "shape.off", {"shape.off", "line 6", "face 0"});
}

TEST(ReadOff, IndexOutOfRangeOrNegative) {
  expect_error<ParseError>("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", MeshFormat::Off,
                           "shape.off", {"shape.off", "line 6", "vertex index 3", "[0, 3)"});
  expect_error<ParseError>("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", MeshFormat::Off,
                           "shape.off", {"shape.off", "line 6", "vertex index -1"});
}

TEST(ReadOff, FaceWithTooFewVertices) {
  expect_error<ParseError>("OFF\n3 1 0\n0.0 0.0 0.0\n1 0 0\n0 1 0\n2 0 1\n", MeshFormat::Off,
                           "shape.off", {"shape.off", "line 6", "face 0 has 2 vertices"});
}

TEST(ReadOff, NonFiniteCoordinates) {
  for (const std::string token : {"nan", "NaN", "inf", "-inf", "infinity", "1e999"}) {
    expect_error<InvalidInputError>("OFF\n3 1 0\n0 0 0\n1 " + token + " 0\n0 1 0\n3 0 1 2\n",
                                    MeshFormat::Off, "shape.off",
                                    {"shape.off", "line 4", "vertex 1", "non-finite", token});
  }
}

TEST(ReadOff, TinyExponentsUnderflowToZero) {
  const Mesh mesh = parse_off("OFF\n3 1 0\n0 0 1e-400\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(mesh.positions[0][2], 0.0);
}

TEST(ReadOff, UnparsableTokens) {
  expect_error<ParseError>("OFF\n3 1 0\n0 0 0\n1 0x 0\n0 1 0\n3 0 1 2\n", MeshFormat::Off,
                           "shape.off", {"shape.off", "line 4", "vertex 1", "'0x'"});
  expect_error<ParseError>("OFF\nthree 1 0\n", MeshFormat::Off, "shape.off",
                           {"shape.off", "line 2", "vertex count", "'three'"});
  expect_error<ParseError>("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", MeshFormat::Off,
                           "shape.off", {"shape.off", "line 6", "'1.5'"});
  expect_error<ParseError>("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\xff 2\n", MeshFormat::Off,
                           "shape.off", {"shape.off", "line 6", "\\xff"});
}

TEST(ReadOff, NoFaces) {
  expect_error<InvalidInputError>("OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", MeshFormat::Off,
                                  "points.off", {"points.off", "line 2", "no faces"});
}

TEST(ReadOff, CountsTheFileCannotHoldAreReportedAtTheHeader) {
  // 4 vertices and 2 faces need at least 40 bytes of text; 26 follow.
  expect_error<ParseError>("OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", MeshFormat::Off,
                           "shape.off",
                           {"shape.off", "line 2", "4 vertices and 2 faces", "at least 40 bytes",
                            "only 26 bytes follow"});
}

TEST(ReadOff, HugeHeaderCountsFailFastWithoutAllocating) {
  const auto start = std::chrono::steady_clock::now();
  expect_error<ParseError>("OFF\n1000000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                           MeshFormat::Off, "huge.off", {"huge.off", "line 2", "1000000000000"});
  expect_error<ParseError>("OFF\n4000000000 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                           MeshFormat::Off, "huge.off",
                           {"huge.off", "line 2", "4000000000 vertices", "bytes follow"});
  expect_error<ParseError>("OFF\n3 1000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", MeshFormat::Off,
                           "huge.off", {"huge.off", "line 2", "1000000 faces", "bytes follow"});
  expect_error<ParseError>("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n", MeshFormat::Off,
                           "huge.off",
                           {"huge.off", "line 6", "2000000000 vertices", "bytes follow"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
}

TEST(ReadOff, UnsupportedVariants) {
  expect_error<ParseError>("OFF BINARY\n\x00\x00", MeshFormat::Off, "b.off",
                           {"b.off", "line 1", "binary OFF"});
  expect_error<ParseError>("nOFF 4\n3 1 0\n", MeshFormat::Off, "n.off",
                           {"n.off", "line 1", "4 dimensions"});
}

}  // namespace
}  // namespace primseg
