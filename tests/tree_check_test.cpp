// A tree given by its parts (a tree file, a caller's merges) must be one build_hierarchy could
// have made: every rule of tree_check.hpp is broken once, behind an otherwise valid tree.
#include "tree_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

struct Parts {
  std::shared_ptr<const Mesh> mesh;
  HierarchyOptions options;
  std::vector<Merge> merges;
};

Parts parts_of(const Hierarchy& h) {
  return {h.shared_mesh(), h.options(), std::vector<Merge>(h.merges().begin(), h.merges().end())};
}

void expect_rejected(const Parts& parts, const std::string& message) {
  try {
    const Hierarchy h(parts.mesh, parts.options, parts.merges);
    ADD_FAILURE() << "accepted; expected an error containing \"" << message << "\"";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

Hierarchy noisy_box() {
  return build_hierarchy(testing::noisy_uniform_shape("box_with_hole"));
}

TEST(TreeCheck, TheBuildersTreesPassAndCutAlike) {
  const Hierarchy built = noisy_box();
  const Parts parts = parts_of(built);
  const Hierarchy copy(parts.mesh, parts.options, parts.merges);
  for (const std::uint32_t k : {1u, 9u, 200u})
    EXPECT_EQ(cut_by_count(copy, k).labels, cut_by_count(built, k).labels);
}

TEST(TreeCheck, MergesWithInconsistentRecordsAreRejected) {
  const Parts valid = parts_of(noisy_box());
  const std::size_t i = valid.merges.size() / 2;  // a real merge: the box is one component
  {
    Parts p = valid;
    std::swap(p.merges[i].first, p.merges[i].second);
    expect_rejected(p, "merge " + std::to_string(i) + " must give its children as first < second");
  }
  {
    Parts p = valid;
    ++p.merges[i].face_count;
    expect_rejected(p, "merge " + std::to_string(i) + " has ");
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const int field : {0, 1, 2})
    for (const double bad : {nan, inf, -1.0}) {
      Parts p = valid;
      (field == 0 ? p.merges[i].cost : field == 1 ? p.merges[i].error : p.merges[i].weight) = bad;
      expect_rejected(p, "negative or non-finite cost, error or weight");
    }
  {
    Parts p = valid;
    p.merges[i].weight *= 1 + 1e-6;
    expect_rejected(p, "merge " + std::to_string(i) + " has a weight that is not the sum");
  }
  {
    Parts p = valid;
    p.merges[i].error = 1e300;
    expect_rejected(p, "an RMS error above 1e30 working units");
  }
  {
    Parts p = valid;
    p.merges[i].cost = 1e305;
    expect_rejected(p, "a cost above 1e300");
  }
  {
    Parts p = valid;
    p.merges[i].primitive.type = PrimitiveType::Torus;
    expect_rejected(p, "a type the tree's options do not enable");
  }
  {
    Parts p = valid;
    p.merges[i].primitive.point[1] = nan;
    expect_rejected(p, "has an invalid primitive");
  }
  {
    Parts p = valid;
    p.merges[i].primitive.type = PrimitiveType::Sphere;
    p.merges[i].primitive.radius = -1;
    expect_rejected(p, "has an invalid primitive");
  }
  {
    Parts p = valid;
    p.merges[i].primitive.type = PrimitiveType::Plane;
    p.merges[i].primitive.axis = {0, 1e-300, 0};
    expect_rejected(p, "has an invalid primitive");
  }
  {
    Parts p = valid;
    p.merges[i].primitive.type = PrimitiveType::Sphere;
    p.merges[i].primitive.radius = 1e200;
    expect_rejected(p, "has an invalid primitive");
  }
}

// Three triangles in a row: 0 and 1 share an edge, 1 and 2 share one, 0 and 2 only a vertex.
std::shared_ptr<const Mesh> strip() {
  return std::make_shared<const Mesh>(Mesh::from_triangles(
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}}, {{0, 1, 2}, {1, 3, 2}, {1, 4, 3}}));
}

// A merge of the strip with a plane and zero error; its weight adds up the faces' weights.
Merge plane_merge(const DualGraph& graph, std::uint32_t first, std::uint32_t second,
                  std::vector<std::uint32_t> faces) {
  Merge m;
  m.first = first;
  m.second = second;
  m.face_count = static_cast<std::uint32_t>(faces.size());
  for (const std::uint32_t f : faces)
    for (const double w : graph.corner_weights(graph.first_triangle(f))) m.weight += w;
  m.primitive.axis = {0, 0, 1};
  return m;
}

TEST(TreeCheck, AMergeOfClustersThatShareNoEdgeIsRejected) {
  const auto mesh = strip();
  const DualGraph graph(*mesh, VertexWeights::Area);
  const Parts adjacent{
      mesh, {}, {plane_merge(graph, 0, 1, {0, 1}), plane_merge(graph, 2, 3, {0, 1, 2})}};
  EXPECT_NO_THROW(Hierarchy(adjacent.mesh, adjacent.options, adjacent.merges));
  const Parts apart{
      mesh, {}, {plane_merge(graph, 0, 2, {0, 2}), plane_merge(graph, 1, 3, {0, 1, 2})}};
  expect_rejected(apart, "merge 0 joins two clusters that share no mesh edge");
}

TEST(TreeCheck, TrailingMergesComeLastAndOnlyBetweenComponents) {
  // Two separate triangle pairs: 2 real merges, then 1 trailing.
  const Mesh two = Mesh::from_triangles(
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {5, 0, 0}, {6, 0, 0}, {5, 1, 0}, {6, 1, 0}},
      {{0, 1, 2}, {1, 3, 2}, {4, 5, 6}, {5, 7, 6}});
  const Hierarchy built = build_hierarchy(two);
  ASSERT_EQ(built.component_count(), 2u);
  const Parts valid = parts_of(built);
  ASSERT_TRUE(valid.merges.back().trailing);
  EXPECT_NO_THROW(Hierarchy(valid.mesh, valid.options, valid.merges));
  {
    Parts p = valid;
    p.merges.back().trailing = false;
    expect_rejected(p, "merge 2 is not trailing: the mesh's 2 components need 2 real merges");
  }
  {
    Parts p = valid;
    p.merges[0].trailing = true;
    expect_rejected(p, "merge 0 is trailing");
  }
}

TEST(TreeCheck, TheCheckAloneNamesTheFirstBadMerge) {
  const Hierarchy built = noisy_box();
  std::vector<Merge> merges(built.merges().begin(), built.merges().end());
  EXPECT_NO_THROW(detail::check_tree_parts(built.graph(), built.options(), merges));
  merges[3].cost = -2;
  merges[7].cost = -2;
  try {
    detail::check_tree_parts(built.graph(), built.options(), merges);
    ADD_FAILURE() << "accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("merge 3 ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace primseg
