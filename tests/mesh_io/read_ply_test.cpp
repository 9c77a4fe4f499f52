// PLY reader: ascii and both binary byte orders, any list and value types, extra properties and
// elements skipped, and errors located by line (header, ascii) or byte offset (binary).

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "mesh_io_test_helpers.hpp"

namespace primseg {
namespace {

using mesh_io_test::Bytes;
using mesh_io_test::expect_error;
using mesh_io_test::expect_tetrahedron;
using mesh_io_test::parse;
using mesh_io_test::tetrahedron_positions;
using mesh_io_test::tetrahedron_triangles;

Mesh parse_ply(std::string_view bytes) {
  return parse(bytes, MeshFormat::Ply, "scan.ply");
}

constexpr std::string_view kAsciiTetrahedron =
    "ply\n"
    "format ascii 1.0\n"
    "comment made by hand\n"
    "obj_info nothing to see\n"
    "element vertex 4\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "property uchar red\n"
    "element face 4\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "0 0 0 255\n"
    "1 0 0 255\n"
    "0 1 0 255\n"
    "0 0 1 255\n"
    "3 0 2 1\n"
    "3 0 1 3\n"
    "3 0 3 2\n"
    "3 1 2 3\n";

TEST(ReadPly, AsciiTetrahedron) {
  expect_tetrahedron(parse_ply(kAsciiTetrahedron));
}

TEST(ReadPly, AsciiWithExtraElementsPropertiesAndPolygons) {
  // CGAL-style: doubles, normals, per-face colour and label, an extra edge element, a quad,
  // vertex_index, CRLF, and the face element before an unrelated one.
  const Mesh mesh = parse_ply(
      "ply\r\nformat ascii 1.0\r\nelement vertex 5\r\nproperty double x\r\nproperty double y\r\n"
      "property double z\r\nproperty double nx\r\nproperty double ny\r\nproperty double nz\r\n"
      "element face 3\r\nproperty list uchar int vertex_index\r\nproperty uchar red\r\n"
      "property int label\r\nelement edge 2\r\nproperty int vertex1\r\nproperty int vertex2\r\n"
      "element material 1\r\nproperty list int uchar name\r\nend_header\r\n"
      "0 0 0 0 0 1\r\n1 0 0 0 0 1\r\n1 1 0 0 0 1\r\n0 1 0 0 0 1\r\n0.5 0.5 1 0 0 1\r\n"
      "4 0 1 2 3 255 7\r\n3 0 1 4 0 8\r\n3 1 2 4 9 9\r\n"
      "0 1\r\n1 2\r\n"
      "3 65 66 67\r\n");
  EXPECT_EQ(mesh.vertex_count(), 5u);
  EXPECT_EQ(mesh.face_count(), 3u);
  EXPECT_EQ(mesh.triangle_count(), 4u);
  EXPECT_EQ(mesh.positions[4], (Vec3{0.5, 0.5, 1.0}));
  EXPECT_EQ(mesh.face_of_triangle, (std::vector<std::uint32_t>{0, 0, 1, 2}));
}

enum class Type { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct TypeInfo {
  Type type;
  std::string_view name;
};

constexpr TypeInfo kTypes[] = {{Type::Int8, "char"},     {Type::UInt8, "uchar"},
                               {Type::Int16, "int16"},   {Type::UInt16, "ushort"},
                               {Type::Int32, "int"},     {Type::UInt32, "uint32"},
                               {Type::Float32, "float"}, {Type::Float64, "float64"}};

void put(Bytes& bytes, Type type, double value) {
  switch (type) {
    case Type::Int8:
      bytes.put(static_cast<std::int8_t>(value));
      break;
    case Type::UInt8:
      bytes.put(static_cast<std::uint8_t>(value));
      break;
    case Type::Int16:
      bytes.put(static_cast<std::int16_t>(value));
      break;
    case Type::UInt16:
      bytes.put(static_cast<std::uint16_t>(value));
      break;
    case Type::Int32:
      bytes.put(static_cast<std::int32_t>(value));
      break;
    case Type::UInt32:
      bytes.put(static_cast<std::uint32_t>(value));
      break;
    case Type::Float32:
      bytes.put(static_cast<float>(value));
      break;
    case Type::Float64:
      bytes.put(value);
      break;
  }
}

/// A binary tetrahedron with distracting extras: a vertex list property before the coordinates,
/// an extra scalar after them, a face property after the index list, and an extra element with
/// a list property between vertices and faces.
std::string binary_tetrahedron(bool big_endian, TypeInfo coordinate, TypeInfo count,
                               TypeInfo index) {
  Bytes bytes(big_endian);
  bytes.text("ply\nformat ")
      .text(big_endian ? "binary_big_endian" : "binary_little_endian")
      .text(" 1.0\ncomment extras\nelement vertex 4\nproperty list uchar float uv\n")
      .text("property ")
      .text(coordinate.name)
      .text(" x\n")
      .text("property ")
      .text(coordinate.name)
      .text(" y\n")
      .text("property ")
      .text(coordinate.name)
      .text(" z\n")
      .text("property ushort quality\nelement material 2\nproperty list int short name\n")
      .text("property double shininess\nelement face 4\n")
      .text("property list ")
      .text(count.name)
      .text(" ")
      .text(index.name)
      .text(" vertex_indices\n")
      .text("property uchar red\nend_header\n");
  const auto& positions = tetrahedron_positions();
  for (std::size_t v = 0; v < positions.size(); ++v) {
    bytes.put(std::uint8_t{static_cast<std::uint8_t>(v % 3)});  // uv list of 0, 1 or 2 floats.
    for (std::size_t i = 0; i < v % 3; ++i) bytes.put(0.25f);
    for (const double c : positions[v]) put(bytes, coordinate.type, c);
    bytes.put(std::uint16_t{77});
  }
  bytes.put(std::int32_t{2}).put(std::int16_t{1}).put(std::int16_t{2}).put(0.5);
  bytes.put(std::int32_t{0}).put(1.5);
  for (const Triangle& t : tetrahedron_triangles()) {
    put(bytes, count.type, 3);
    for (const std::uint32_t v : t) put(bytes, index.type, v);
    bytes.put(std::uint8_t{200});
  }
  return bytes.str();
}

TEST(ReadPly, BinaryLittleEndianFloat) {
  expect_tetrahedron(parse_ply(binary_tetrahedron(false, kTypes[6], kTypes[1], kTypes[4])));
}

TEST(ReadPly, BinaryBigEndianDoubleWithUcharAndIntLists) {
  expect_tetrahedron(parse_ply(binary_tetrahedron(true, kTypes[7], kTypes[1], kTypes[4])));
}

TEST(ReadPly, AnyCountTypeAnyIndexTypeBothByteOrders) {
  for (const bool big_endian : {false, true}) {
    for (const TypeInfo& count : kTypes) {
      for (const TypeInfo& index : kTypes) {
        SCOPED_TRACE(std::string(big_endian ? "big" : "little") + " list " +
                     std::string(count.name) + " " + std::string(index.name));
        expect_tetrahedron(parse_ply(binary_tetrahedron(big_endian, kTypes[7], count, index)));
      }
    }
  }
  for (const TypeInfo& coordinate : kTypes) {
    SCOPED_TRACE(coordinate.name);
    expect_tetrahedron(parse_ply(binary_tetrahedron(true, coordinate, kTypes[0], kTypes[2])));
  }
}

TEST(ReadPly, BigEndianDoublesAreExact) {
  Bytes bytes(/*big_endian=*/true);
  bytes.text(
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n"
      "property double y\nproperty double z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n");
  const double values[9] = {0.1,    -1e-300,    1e300, 3.141592653589793, 2.0 / 3.0, -0.0,
                            5e-324, 123456.789, -7.0};
  for (const double v : values) bytes.put(v);
  bytes.put(std::uint8_t{3}).put(std::int32_t{0}).put(std::int32_t{1}).put(std::int32_t{2});
  const Mesh mesh = parse_ply(bytes.str());
  for (int i = 0; i < 9; ++i) {
    EXPECT_EQ(std::signbit(mesh.positions[i / 3][i % 3]), std::signbit(values[i]));
    EXPECT_EQ(mesh.positions[i / 3][i % 3], values[i]);
  }
}

std::string binary_header(std::string_view format, int vertices, int faces) {
  return "ply\nformat " + std::string(format) + " 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

std::string little_endian_triangle(float z_of_vertex_1, std::int32_t last_index) {
  Bytes bytes;
  bytes.text(binary_header("binary_little_endian", 3, 1));
  for (const float c : {0.0f, 0.0f, 0.0f, 1.0f, 0.0f, z_of_vertex_1, 0.0f, 1.0f, 0.0f}) {
    bytes.put(c);
  }
  bytes.put(std::uint8_t{3}).put(std::int32_t{0}).put(std::int32_t{1}).put(last_index);
  return bytes.str();
}

// Byte offsets in the triangle file: the header, 3 vertices of 12 bytes, then the face record
// (uchar length, 3 int indices).
const std::size_t kHeader = binary_header("binary_little_endian", 3, 1).size();
const std::size_t kFace = kHeader + 36;

std::string at(std::size_t offset) {
  return "byte offset " + std::to_string(offset);
}

TEST(ReadPly, BinaryTriangleBaseline) {
  const std::string file = little_endian_triangle(0.0f, 2);
  EXPECT_EQ(parse_ply(file).triangles, (std::vector<Triangle>{{0, 1, 2}}));
  EXPECT_EQ(file.size(), kFace + 13);
}

TEST(ReadPly, TruncatedBinary) {
  const std::string file = little_endian_triangle(0.0f, 2);
  // Faces first, then vertices cut inside vertex 2: the list lengths used up the bytes the
  // header check counted on.
  Bytes faces_first;
  faces_first.text(
      "ply\nformat binary_little_endian 1.0\nelement face 1\n"
      "property list uchar int vertex_indices\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n");
  const std::size_t vertices = faces_first.str().size() + 13;
  faces_first.put(std::uint8_t{3}).put(0).put(1).put(2);
  for (int i = 0; i < 7; ++i) faces_first.put(1.0f);
  expect_error<ParseError>(faces_first.str(), MeshFormat::Ply, "scan.ply",
                           {"scan.ply", at(vertices + 24), "record 2 of the 3", "'vertex'"});
  // Inside the face's index list.
  expect_error<ParseError>(file.substr(0, file.size() - 2), MeshFormat::Ply, "scan.ply",
                           {"scan.ply", at(kFace), "record 0", "'face'"});
  // Too short for the declared records: reported at the declaration, before reading.
  expect_error<ParseError>(file.substr(0, kHeader + 20), MeshFormat::Ply, "scan.ply",
                           {"scan.ply", "line 3", "'vertex'", "only 20 bytes follow"});
  expect_error<ParseError>(file.substr(0, kHeader), MeshFormat::Ply, "scan.ply",
                           {"scan.ply", "line 3", "'vertex'", "only 0 bytes follow"});
  // Cut inside the header.
  expect_error<ParseError>(file.substr(0, kHeader - 3), MeshFormat::Ply, "scan.ply",
                           {"scan.ply", "line 9", "end_head"});
}

TEST(ReadPly, BinaryElementCountsDoNotMatchTheData) {
  expect_error<ParseError>(little_endian_triangle(0.0f, 2) + "junk", MeshFormat::Ply, "scan.ply",
                           {"scan.ply", at(kFace + 13), "4 bytes", "counts"});
}

TEST(ReadPly, BinaryIndexOutOfRangeOrNegative) {
  expect_error<ParseError>(little_endian_triangle(0.0f, 3), MeshFormat::Ply, "scan.ply",
                           {"scan.ply", at(kFace + 9), "face 0", "vertex index 3"});
  expect_error<ParseError>(little_endian_triangle(0.0f, -1), MeshFormat::Ply, "scan.ply",
                           {"scan.ply", at(kFace + 9), "vertex index -1"});
}

TEST(ReadPly, BinaryNonFiniteCoordinate) {
  expect_error<InvalidInputError>(little_endian_triangle(NAN, 2), MeshFormat::Ply, "scan.ply",
                                  {"scan.ply", at(kHeader + 12), "vertex 1", "non-finite"});
  expect_error<InvalidInputError>(little_endian_triangle(-INFINITY, 2), MeshFormat::Ply, "scan.ply",
                                  {"scan.ply", at(kHeader + 12), "non-finite"});
}

TEST(ReadPly, BinaryErrorsInRecordsOfVaryingSize) {
  // An element with a list property is read record by record, not as a block of fixed-size
  // records: its coordinates and list lengths are checked on that path too.
  Bytes with_uv;
  with_uv.text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty list uchar float uv\n"
      "property float x\nproperty float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n");
  const std::size_t vertices = with_uv.str().size();
  for (const float z : {0.0f, NAN, 0.0f}) with_uv.put(std::uint8_t{0}).put(0.0f).put(1.0f).put(z);
  with_uv.put(std::uint8_t{3}).put(std::int32_t{0}).put(std::int32_t{1}).put(std::int32_t{2});
  // Each vertex record is 13 bytes: an empty uv list and three floats.
  expect_error<InvalidInputError>(with_uv.str(), MeshFormat::Ply, "scan.ply",
                                  {"scan.ply", at(vertices + 13), "vertex 1", "non-finite"});

  // A signed list length below zero.
  std::string header = binary_header("binary_little_endian", 3, 1);
  header.replace(header.find("uchar"), 5, "char");
  Bytes negative;
  negative.text(header);
  for (int i = 0; i < 9; ++i) negative.put(0.0f);
  negative.put(std::int8_t{-1}).put(std::int32_t{0});
  expect_error<ParseError>(
      negative.str(), MeshFormat::Ply, "scan.ply",
      {"scan.ply", at(header.size() + 36), "invalid list length -1 in record 0 of element 'face'"});
}

TEST(ReadPly, FaceIndicesThatAreNotAList) {
  expect_error<ParseError>(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n0\n",
      MeshFormat::Ply, "flat.ply", {"flat.ply", "line 7", "'vertex_indices' is not a list"});
}

TEST(ReadPly, HugeElementCountsFailFast) {
  Bytes bytes;
  bytes.text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n");
  bytes.put(0.0f);
  expect_error<ParseError>(bytes.str(), MeshFormat::Ply, "huge.ply",
                           {"huge.ply", "line 3", "1000000000000"});
  expect_error<ParseError>(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 4000000000\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
      MeshFormat::Ply, "huge.ply", {"huge.ply", "line 7", "4000000000 records", "bytes follow"});
  // A list claiming 4 billion entries in a 200-byte file.
  Bytes list(/*big_endian=*/true);
  std::string header = binary_header("binary_big_endian", 3, 1);
  header.replace(header.find("uchar"), 5, "uint");
  list.text(header);
  for (int i = 0; i < 9; ++i) list.put(0.0f);
  list.put(std::uint32_t{4000000000u}).put(std::int32_t{0});
  expect_error<ParseError>(list.str(), MeshFormat::Ply, "huge.ply",
                           {"huge.ply", "byte offset", "ends inside record 0"});
}

TEST(ReadPly, AsciiErrors) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  // Lines 10-12 hold the vertices, line 13 the face.
  expect_error<ParseError>(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", MeshFormat::Ply, "a.ply",
                           {"a.ply", "line 13", "vertex index 3"});
  expect_error<ParseError>(header + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", MeshFormat::Ply, "a.ply",
                           {"a.ply", "line 13", "vertex index -1"});
  expect_error<ParseError>(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1\n", MeshFormat::Ply, "a.ply",
                           {"a.ply", "line 14", "end of file"});
  expect_error<ParseError>(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n", MeshFormat::Ply,
                           "a.ply", {"a.ply", "line 14", "counts do not match"});
  expect_error<ParseError>(header + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", MeshFormat::Ply, "a.ply",
                           {"a.ply", "line 13", "face 0 has 2 vertices"});
  expect_error<ParseError>(header + "0 0 0\n1 O 0\n0 1 0\n3 0 1 2\n", MeshFormat::Ply, "a.ply",
                           {"a.ply", "line 11", "'O'"});
  expect_error<InvalidInputError>(header + "0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n", MeshFormat::Ply,
                                  "a.ply", {"a.ply", "line 12", "vertex 2", "'nan'"});
  // Lists may be stored as floats; their values must still be whole numbers.
  const std::string float_lists =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list float float vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_EQ(parse(float_lists + "3 0 1 2\n", MeshFormat::Ply).face_count(), 1u);
  expect_error<ParseError>(float_lists + "3 0 1.5 2\n", MeshFormat::Ply, "a.ply",
                           {"a.ply", "line 13", "vertex index 1.5, not a whole number"});
  expect_error<ParseError>(float_lists + "3.5 0 1 2\n", MeshFormat::Ply, "a.ply",
                           {"a.ply", "line 13", "invalid list length 3.5 "});
}

TEST(ReadPly, HeaderErrors) {
  expect_error<ParseError>("", MeshFormat::Ply, "h.ply", {"h.ply", "line 1", "empty"});
  expect_error<ParseError>("OFF\n3 1 0\n", MeshFormat::Ply, "h.ply",
                           {"h.ply", "line 1", "not a PLY file"});
  expect_error<ParseError>("ply\nformat ascii 1.0\nelement vertex 3\n", MeshFormat::Ply, "h.ply",
                           {"h.ply", "line 4", "end_header"});
  expect_error<ParseError>("ply\nformat binary_middle_endian 1.0\nend_header\n", MeshFormat::Ply,
                           "h.ply", {"h.ply", "line 2", "binary_middle_endian"});
  expect_error<ParseError>(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float128 x\nend_header\n", MeshFormat::Ply,
      "h.ply", {"h.ply", "line 4", "'float128'"});
  expect_error<ParseError>(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n",
      MeshFormat::Ply, "h.ply", {"h.ply", "line 3", "'z'"});
}

TEST(ReadPly, NoFaces) {
  // A point cloud, like CGAL's b9.ply.
  expect_error<InvalidInputError>(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n",
      MeshFormat::Ply, "cloud.ply", {"cloud.ply", "line 7", "no faces"});
  expect_error<InvalidInputError>(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
      MeshFormat::Ply, "cloud.ply", {"cloud.ply", "line 8", "no faces"});
}

}  // namespace
}  // namespace primseg
