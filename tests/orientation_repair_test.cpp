#include "orientation_repair.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace primseg {
namespace {

// A strip of triangles along x in the plane z = 0, all facing +z: vertices 2i (y = 0) and
// 2i + 1 (y = 1) at x = i.
struct Strip {
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;
  std::vector<Vec3> normals;  // facing +z, of any length
};

Strip strip(std::uint32_t columns) {
  Strip s;
  for (std::uint32_t i = 0; i < columns; ++i) {
    s.positions.push_back({double(i), 0, 0});
    s.positions.push_back({double(i), 1, 0});
  }
  for (std::uint32_t i = 0; i + 1 < columns; ++i) {
    s.triangles.push_back({2 * i, 2 * i + 2, 2 * i + 3});
    s.triangles.push_back({2 * i, 2 * i + 3, 2 * i + 1});
  }
  s.normals.assign(s.triangles.size(), Vec3{0, 0, 2});
  return s;
}

TEST(OrientationRepair, KeepsPositionsThatInvertNothing) {
  const Strip s = strip(4);
  std::vector<Vec3> moved = s.positions;
  moved[3] = {1.2, 0.9, 0.3};  // moved, but every triangle still faces +z
  const std::vector<Vec3> before = moved;
  EXPECT_EQ(revert_inverted_triangles(moved, s.positions, s.triangles, s.normals), 0u);
  EXPECT_EQ(moved, before);
}

TEST(OrientationRepair, PutsBackTheVerticesOfAnInvertedTriangle) {
  const Strip s = strip(4);
  std::vector<Vec3> moved = s.positions;
  for (Vec3& p : moved) p[2] += 0.01;  // a move everywhere, to see which vertices go back
  moved[3][0] = 3.5;                   // (1, 1) beyond (2, 1): triangle 3 (2, 5, 3) turns over
  EXPECT_EQ(revert_inverted_triangles(moved, s.positions, s.triangles, s.normals), 3u);
  // Its vertices go back; the others, on no inverted triangle, keep their move.
  for (std::uint32_t v = 0; v < 8; ++v) {
    const bool back = v == 2 || v == 3 || v == 5;
    EXPECT_EQ(moved[v] == s.positions[v], back) << v;
  }
}

TEST(OrientationRepair, PutsBackAgainWhereAPutBackVertexInvertsANeighbour) {
  // Everything shifted by +3 in x but vertex 5, which turns triangle 3 (2, 5, 3) over. Putting
  // back its vertices 2, 3 and 5 turns triangles 0 and 1 over (vertices 0 and 1 are still
  // shifted), a later pass puts back 0 and 1, and then every triangle faces +z.
  const Strip s = strip(5);
  std::vector<Vec3> moved = s.positions;
  for (Vec3& p : moved) p[0] += 3;
  moved[5][0] = s.positions[5][0];
  EXPECT_EQ(revert_inverted_triangles(moved, s.positions, s.triangles, s.normals), 5u);
  for (std::uint32_t v = 0; v < 10; ++v)
    EXPECT_EQ(moved[v] == s.positions[v], v < 6 && v != 4) << v;  // 4 keeps its shift
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const Vec3 &a = moved[s.triangles[t][0]], &b = moved[s.triangles[t][1]],
               &c = moved[s.triangles[t][2]];
    const double z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    EXPECT_GE(z, 0) << t;
  }
}

TEST(OrientationRepair, AFlattenedTriangleIsNotInverted) {
  const Strip s = strip(2);
  std::vector<Vec3> moved = s.positions;
  moved[3] = {0.5, 0, 0};  // on the edge from 0 to 2: triangle 0 has zero area
  EXPECT_EQ(revert_inverted_triangles(moved, s.positions, s.triangles, s.normals), 0u);
}

}  // namespace
}  // namespace primseg
