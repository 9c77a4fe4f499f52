// Lazy candidate evaluation: the same tree as the eager reference, bit for bit, with fewer
// evaluations where bounds hold.
#include <gtest/gtest.h>

#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"
#include "primseg/tree_io.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

struct Build {
  std::string tree;
  std::uint64_t evaluations = 0;
  Hierarchy hierarchy;
};

Build build(const Mesh& mesh, std::vector<PrimitiveType> primitives,
            CandidateEvaluation evaluation) {
  HierarchyOptions options;
  options.primitives = std::move(primitives);
  options.evaluation = evaluation;
  HierarchyBuilder builder(std::make_shared<const Mesh>(mesh), options);
  Hierarchy hierarchy = builder.finish();
  return {serialize_tree(hierarchy), builder.evaluation_count(), std::move(hierarchy)};
}

const std::vector<PrimitiveType> kAll{PrimitiveType::Plane, PrimitiveType::Cylinder,
                                      PrimitiveType::Sphere};
const std::vector<PrimitiveType> kPlaneSphere{PrimitiveType::Plane, PrimitiveType::Sphere};

Mesh noisy_shape(const std::string& name, std::uint64_t seed) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.noise = 0.002;
  options.random_motion = true;
  options.seed = seed;
  return make_shape(name, options).mesh;
}

void expect_lazy_equals_eager(const Mesh& mesh, const std::vector<PrimitiveType>& primitives,
                              const std::string& what, bool expect_savings) {
  const Build eager = build(mesh, primitives, CandidateEvaluation::Eager);
  const Build lazy = build(mesh, primitives, CandidateEvaluation::Lazy);
  EXPECT_EQ(lazy.tree, eager.tree) << what;
  EXPECT_LE(lazy.evaluations, eager.evaluations) << what;
  if (expect_savings) {
    EXPECT_LT(lazy.evaluations, eager.evaluations * 9 / 10) << what;
  }
}

TEST(LazyEvaluation, SameTreeAsEagerOnNoisyGeneratedShapes) {
  std::uint64_t seed = 1;
  for (const std::string& name : shape_names()) {
    const Mesh mesh = noisy_shape(name, seed++);
    expect_lazy_equals_eager(mesh, kAll, name + " all types", false);
    expect_lazy_equals_eager(mesh, kPlaneSphere, name + " plane+sphere", true);
  }
}

TEST(LazyEvaluation, SameTreeAsEagerOnFandiskAndBunny) {
  const Mesh fandisk = read_mesh(testing::cgal_mesh("fandisk.off"));
  expect_lazy_equals_eager(fandisk, kAll, "fandisk all types", false);
  expect_lazy_equals_eager(fandisk, kPlaneSphere, "fandisk plane+sphere", true);
  const Mesh bunny = read_mesh(testing::cgal_mesh("bunny00.off"));
  expect_lazy_equals_eager(bunny, kPlaneSphere, "bunny00 plane+sphere", false);
}

TEST(LazyEvaluation, ExactCostModeIsAlwaysEager) {
  const Mesh mesh = noisy_shape("box_with_hole", 7);
  HierarchyOptions options;
  options.exact_costs = true;
  options.evaluation = CandidateEvaluation::Eager;
  const std::string eager = serialize_tree(build_hierarchy(mesh, options));
  options.evaluation = CandidateEvaluation::Lazy;
  EXPECT_EQ(serialize_tree(build_hierarchy(mesh, options)), eager);
}

}  // namespace
}  // namespace primseg
