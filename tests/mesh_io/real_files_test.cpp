// Real meshes from Debian's libcgal-demo (extracted at test time, never committed).

#include <gtest/gtest.h>

#include "mesh_io_test_helpers.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using mesh_io_test::write_options;

TEST(RealFiles, FandiskOff) {
  const Mesh mesh = read_mesh(testing::cgal_mesh("fandisk.off"));
  EXPECT_EQ(mesh.vertex_count(), 6475u);
  EXPECT_EQ(mesh.face_count(), 12946u);
  EXPECT_EQ(mesh.triangle_count(), 12946u);
  EXPECT_EQ(mesh.positions[0], (Vec3{0.1696, 0.04095, -0.0471}));
  EXPECT_NO_THROW(mesh.validate());
}

TEST(RealFiles, Bunny00Off) {
  const Mesh mesh = read_mesh(testing::cgal_mesh("bunny00.off"));
  EXPECT_EQ(mesh.vertex_count(), 37706u);
  EXPECT_EQ(mesh.face_count(), 75408u);
  EXPECT_EQ(mesh.positions[1], (Vec3{-0.436321, -0.205135, 0.0771522}));
}

TEST(RealFiles, PlyFiles) {
  const Mesh sphere = read_mesh(testing::cgal_mesh("sphere.ply"));
  EXPECT_EQ(sphere.vertex_count(), 162u);
  EXPECT_EQ(sphere.face_count(), 320u);
  EXPECT_EQ(sphere.positions[1], (Vec3{0.44719999999999999, 0.22359999999999999, 0.0}));
  // Normals, colours, ids, per-face colours and labels, and an edge element.
  const Mesh tetra = read_mesh(testing::cgal_mesh("colored_tetra.ply"));
  EXPECT_EQ(tetra.vertex_count(), 4u);
  EXPECT_EQ(tetra.face_count(), 4u);
  // A point cloud: no faces.
  try {
    read_mesh(testing::cgal_mesh("b9.ply"));
    FAIL() << "b9.ply has no faces";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("b9.ply: line 8: mesh has no faces"),
              std::string::npos)
        << error.what();
  }
}

TEST(RealFiles, BinaryStlFilesAreWelded) {
  // Vertex counts from welding the corners' raw bytes independently (a Python one-liner).
  const Mesh sphere = read_mesh(testing::cgal_mesh("sphere.stl"));
  EXPECT_EQ(sphere.face_count(), 320u);
  EXPECT_EQ(sphere.vertex_count(), 162u);                     // Closed: V = F / 2 + 2.
  const Mesh pig = read_mesh(testing::cgal_mesh("pig.stl"));  // Open, 1296 boundary edges.
  EXPECT_EQ(pig.face_count(), 16848u);
  EXPECT_EQ(pig.vertex_count(), 8642u);
}

TEST(RealFiles, BunnyRoundTripsThroughEveryFormat) {
  const Mesh mesh = read_mesh(testing::cgal_mesh("bunny00.off"));
  const std::filesystem::path directory = testing::temp_directory("mesh_io_real");
  for (const char* name : {"b.off", "b.obj", "b.ply"}) {
    write_mesh(directory / name, mesh);
    const Mesh back = read_mesh(directory / name);
    EXPECT_EQ(back.positions, mesh.positions) << name;
    EXPECT_EQ(back.triangles, mesh.triangles) << name;
  }
  write_mesh(directory / "b.stl", mesh, write_options({}, {}, false));
  const Mesh stl = read_mesh(directory / "b.stl");
  EXPECT_EQ(stl.triangle_count(), mesh.triangle_count());
  EXPECT_LE(stl.vertex_count(), mesh.vertex_count());  // Isolated vertices are not in STL.
  std::filesystem::remove_all(directory);
}

}  // namespace
}  // namespace primseg
