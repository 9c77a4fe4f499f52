// The benchmark's evaluation tape (src/evaluation_tape.hpp): a build that replays the recorded
// outcomes instead of evaluating builds the same tree, bit for bit, and a tape that does not fit
// the build is refused with a message, not followed.
#include <gtest/gtest.h>

#include "evaluation_tape.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/tree_io.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using Mode = detail::EvaluationTape::Mode;

// Leaves the global tape Off, whatever the test did.
class EvaluationTapeTest : public ::testing::Test {
 protected:
  void TearDown() override { detail::evaluation_tape = {}; }
};

std::string tree_bytes(const Mesh& mesh, const HierarchyOptions& options, Mode mode,
                       std::uint64_t* evaluations = nullptr) {
  detail::evaluation_tape.mode = mode;
  detail::evaluation_tape.next = 0;
  HierarchyBuilder builder(std::make_shared<const Mesh>(mesh), options);
  const std::string bytes = serialize_tree(builder.finish());
  if (evaluations) *evaluations = builder.evaluation_count();
  detail::evaluation_tape.mode = Mode::Off;
  return bytes;
}

void expect_replay_builds_the_same_tree(const Mesh& mesh, const HierarchyOptions& options,
                                        const std::string& what) {
  std::uint64_t evaluations = 0;
  const std::string real = tree_bytes(mesh, options, Mode::Off, &evaluations);
  detail::evaluation_tape.outcomes.clear();
  EXPECT_EQ(tree_bytes(mesh, options, Mode::Record), real) << what;
  EXPECT_EQ(detail::evaluation_tape.outcomes.size(), evaluations) << what;
  EXPECT_EQ(tree_bytes(mesh, options, Mode::Replay), real) << what;
  EXPECT_EQ(detail::evaluation_tape.next, evaluations) << what;
}

HierarchyOptions one_thread() {
  HierarchyOptions options;
  options.threads = 1;
  return options;
}

TEST_F(EvaluationTapeTest, ReplayBuildsTheSameTreeAsEvaluating) {
  const Mesh noisy = testing::noisy_uniform_shape("box_with_hole");
  expect_replay_builds_the_same_tree(noisy, one_thread(), "default types");
  // Planes and spheres: lazy evaluation queues bounds, which the tape carries too.
  HierarchyOptions lazy = one_thread();
  lazy.primitives = {PrimitiveType::Plane, PrimitiveType::Sphere};
  expect_replay_builds_the_same_tree(noisy, lazy, "plane+sphere");
  HierarchyOptions batched = one_thread();
  batched.merge_batch_tolerance = 0.1;
  expect_replay_builds_the_same_tree(noisy, batched, "batched");
  // Exact ties at cost zero, ranked by degree.
  expect_replay_builds_the_same_tree(make_shape("box_with_boss").mesh, one_thread(), "clean CAD");
}

TEST_F(EvaluationTapeTest, RefusesSeveralThreadsAndRegions) {
  const Mesh mesh = testing::noisy_uniform_shape("box");
  HierarchyOptions two_threads;
  two_threads.threads = 2;
  detail::evaluation_tape.mode = Mode::Record;
  EXPECT_THROW(HierarchyBuilder(std::make_shared<const Mesh>(mesh), two_threads), Error);
  HierarchyOptions regions = one_thread();
  regions.regions = 2;
  EXPECT_THROW(HierarchyBuilder(std::make_shared<const Mesh>(mesh), regions), Error);
}

TEST_F(EvaluationTapeTest, RefusesATapeShorterThanTheBuild) {
  const Mesh mesh = testing::noisy_uniform_shape("box");
  detail::evaluation_tape.outcomes.clear();
  tree_bytes(mesh, one_thread(), Mode::Record);
  detail::evaluation_tape.outcomes.resize(detail::evaluation_tape.outcomes.size() / 2);
  try {
    tree_bytes(mesh, one_thread(), Mode::Replay);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("more candidates than it recorded"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace primseg
