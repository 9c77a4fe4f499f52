// OBJ reader: the statements that shape the surface, everything else ignored, and errors.

#include <gtest/gtest.h>

#include <string>

#include "mesh_io_test_helpers.hpp"

namespace primseg {
namespace {

using mesh_io_test::expect_error;
using mesh_io_test::expect_tetrahedron;
using mesh_io_test::parse;

Mesh parse_obj(std::string_view text) {
  return parse(text, MeshFormat::Obj, "model.obj");
}

TEST(ReadObj, TetrahedronWithEveryCornerSyntax) {
  expect_tetrahedron(
      parse_obj("# exported\nmtllib model.mtl\no tetra\n"
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nvn 1 0 0\n"
                "g side\nusemtl red\ns 1\n"
                "f 1 3 2\n"
                "f 1/1 2/2 4/3\n"
                "f 1//1 4//2 3//1\n"
                "f 2/1/1 3/2/2 4/3/1\n"
                "l 1 2\n"));
}

TEST(ReadObj, NegativeIndicesCountBackFromTheLastVertex) {
  expect_tetrahedron(
      parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -1 -2\nv 0 0 1\n"
                "f -4 -3 -1\nf 1 -1 -2\nf -3/1/1 -2//2 -1\n"));
}

TEST(ReadObj, ExtraVertexValuesAndLayoutAreTolerated) {
  // w, vertex colours, CRLF, tabs, leading blanks, trailing comment, no final newline.
  expect_tetrahedron(
      parse_obj("v 0 0 0 1\r\nv\t1 0 0 1.0 0.5 0.5\r\n  v 0 1 0 0.1 0.2 0.3\r\nv 0 0 1\r\n\r\n"
                "f 1 3 2 # bottom\r\nf 1 2 4\r\nf 1 4 3\r\nf 2 3 4"));
}

TEST(ReadObj, PolygonsAndForwardReferences) {
  // A quad and a pentagon, the pentagon listed before its last vertex (allowed by some writers).
  const Mesh mesh = parse_obj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nv 2 0 0\nf 2 6 7 3 5\n"
      "v 3 0 0\nv 3 1 0\n");
  EXPECT_EQ(mesh.vertex_count(), 7u);
  EXPECT_EQ(mesh.face_count(), 2u);
  EXPECT_EQ(mesh.triangle_count(), 5u);
  EXPECT_EQ(mesh.face_of_triangle, (std::vector<std::uint32_t>{0, 0, 1, 1, 1}));
  EXPECT_EQ(mesh.polygon(1)[1], 5u);
}

TEST(ReadObj, IndexZeroIsAnError) {
  expect_error<ParseError>("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", MeshFormat::Obj, "model.obj",
                           {"model.obj", "line 4", "index 0"});
}

TEST(ReadObj, IndexOutOfRange) {
  expect_error<ParseError>("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n# end\n", MeshFormat::Obj,
                           "model.obj", {"model.obj", "line 5", "vertex 4", "3 vertices"});
  expect_error<ParseError>("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", MeshFormat::Obj, "model.obj",
                           {"model.obj", "line 4", "-4", "before the first vertex"});
  expect_error<ParseError>("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n",
                           MeshFormat::Obj, "model.obj", {"model.obj", "line 4"});
  // A whole number, but beyond what 32-bit vertex ids address: refused where it stands, before
  // the file's end could show whether it was a forward reference.
  expect_error<ParseError>("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4294967296\nf 1 2 3\n",
                           MeshFormat::Obj, "model.obj",
                           {"model.obj", "line 4", "vertex index 4294967296 is too large"});
}

TEST(ReadObj, MalformedStatements) {
  expect_error<ParseError>("v 0 0 0\nv 1 0\nv 0 1 0\n", MeshFormat::Obj, "model.obj",
                           {"model.obj", "line 2", "coordinate", "end of line"});
  expect_error<ParseError>("v 0 0 0\nv 1 zero 0\n", MeshFormat::Obj, "model.obj",
                           {"model.obj", "line 2", "'zero'"});
  expect_error<ParseError>("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a3\n", MeshFormat::Obj, "model.obj",
                           {"model.obj", "line 4", "'a3'"});
  expect_error<ParseError>("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", MeshFormat::Obj, "model.obj",
                           {"model.obj", "line 4", "2 vertices"});
}

TEST(ReadObj, NonFiniteCoordinates) {
  expect_error<InvalidInputError>("v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n", MeshFormat::Obj,
                                  "model.obj", {"model.obj", "line 3", "vertex 2", "'nan'"});
  expect_error<InvalidInputError>("v 0 0 0\nv 1 0 -inf\nv 0 1 0\nf 1 2 3\n", MeshFormat::Obj,
                                  "model.obj", {"model.obj", "line 2", "'-inf'"});
}

TEST(ReadObj, EmptyOrFaceless) {
  expect_error<ParseError>("", MeshFormat::Obj, "model.obj", {"model.obj", "line 1", "empty"});
  expect_error<InvalidInputError>("v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n", MeshFormat::Obj,
                                  "cloud.obj", {"cloud.obj", "line 5", "no faces"});
}

}  // namespace
}  // namespace primseg
