// The tree file: a faithful, self-contained, checked copy of a hierarchy.
#include "primseg/tree_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

Hierarchy sample_hierarchy() {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.noise = 0.001;
  return build_hierarchy(make_shape("box_with_hole", options).mesh);
}

TEST(TreeIo, RoundTripKeepsEveryMergeAndCut) {
  const Hierarchy h = sample_hierarchy();
  const std::string bytes = serialize_tree(h);
  const Hierarchy copy = deserialize_tree(bytes);
  ASSERT_EQ(copy.merges().size(), h.merges().size());
  EXPECT_EQ(serialize_tree(copy), bytes);
  for (std::uint32_t k : {1u, 7u, 50u}) {
    EXPECT_EQ(cut_by_count(copy, k).labels, cut_by_count(h, k).labels);
    const auto a = describe_clusters(h, cut_by_count(h, k));
    const auto b = describe_clusters(copy, cut_by_count(copy, k));
    for (std::size_t c = 0; c < a.size(); ++c) {
      EXPECT_EQ(a[c].primitive.type, b[c].primitive.type);
      EXPECT_EQ(a[c].rms, b[c].rms);
    }
  }
  const auto dir = testing::temp_directory("tree");
  write_tree(dir / "t.tree", h);
  EXPECT_EQ(serialize_tree(read_tree(dir / "t.tree")), bytes);
}

TEST(TreeIo, CorruptTruncatedAndForeignFilesGiveClearErrors) {
  const std::string bytes = serialize_tree(sample_hierarchy());
  std::string flipped = bytes;
  flipped[flipped.size() / 2] ^= 0x10;
  try {
    deserialize_tree(flipped, "x.tree");
    FAIL() << "corrupt file accepted";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("checksum"), std::string::npos) << e.what();
  }
  EXPECT_THROW(deserialize_tree(std::string_view(bytes).substr(0, bytes.size() / 3)), ParseError);
  EXPECT_THROW(deserialize_tree(std::string_view(bytes).substr(0, 5)), ParseError);
  EXPECT_THROW(deserialize_tree(std::string("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")),
               ParseError);
  EXPECT_THROW(deserialize_tree(std::string()), ParseError);
  EXPECT_THROW(read_tree("/nonexistent/primseg.tree"), IoError);
}

// The checksum guards against accidents, not against a writer that gets the content wrong: every
// content check must hold behind a valid checksum too (FNV-1a 64, as docs/tree-format.md says).
std::string with_checksum(std::string body) {
  std::uint64_t hash = 14695981039346656037ull;
  for (const char c : body) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ull;
  }
  for (int i = 0; i < 8; ++i) body.push_back(static_cast<char>((hash >> (8 * i)) & 0xff));
  return body;
}

void expect_parse_error(const std::string& bytes, const std::string& message) {
  try {
    deserialize_tree(bytes, "x.tree");
    ADD_FAILURE() << "accepted; expected an error containing \"" << message << "\"";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("x.tree"), std::string::npos) << e.what();
  }
}

TEST(TreeIo, BadContentIsRejectedBehindAValidChecksum) {
  const std::string bytes = serialize_tree(sample_hierarchy());
  const std::string body = bytes.substr(0, bytes.size() - 8);
  ASSERT_EQ(with_checksum(body), bytes);  // the test's checksum is the format's
  // Offsets from docs/tree-format.md: magic 8, version u32, weights u8, exact_costs u8, n u8,
  // then the n types.
  constexpr std::size_t kVersion = 8, kWeights = 12, kFirstType = 15;

  std::string version = body;
  version[kVersion] = 2;
  expect_parse_error(with_checksum(version), "version 2 is not supported");

  std::string weights = body;
  weights[kWeights] = 2;
  expect_parse_error(with_checksum(weights), "unknown vertex weighting 2");

  std::string type = body;
  type[kFirstType] = 9;
  expect_parse_error(with_checksum(type), "unknown primitive type 9");

  constexpr std::size_t kExactCosts = 13;
  std::string exact_costs = body;
  exact_costs[kExactCosts] = 2;
  expect_parse_error(with_checksum(exact_costs), "exact_costs must be 0 or 1, not 2");

  // A merge: first, second (u32), cost, error, weight (f64), face_count (u32), then trailing.
  std::string trailing = body;
  trailing[body.size() - 110 + 4 + 4 + 3 * 8 + 4] = 7;
  expect_parse_error(with_checksum(trailing), "trailing flag must be 0 or 1, not 7");

  // Content the reader parses but the tree cannot hold: a negative cost.
  std::string negative_cost = body;
  negative_cost[body.size() - 110 + 8 + 7] = static_cast<char>(0xbf);  // sign and exponent of -x
  expect_parse_error(with_checksum(negative_cost), "invalid tree: merge");

  expect_parse_error(with_checksum(body + "extra"), "unexpected data after the merges");
  expect_parse_error(with_checksum(body.substr(0, body.size() - 1)), "exceeds the file size");

  // The last merge (110 bytes before the checksum) names its second child as its first.
  std::string self_merge = body;
  const std::size_t last = body.size() - 110;
  std::copy_n(body.begin() + static_cast<std::ptrdiff_t>(last), 4,
              self_merge.begin() + static_cast<std::ptrdiff_t>(last + 4));
  expect_parse_error(with_checksum(self_merge), "invalid tree");
}

// The tree fuzzer's inputs in fuzz/<folder>/<kind>/, by file name: tree files without their
// checksum (the fuzzer appends it), returned with it.
std::vector<std::pair<std::string, std::string>> fuzz_tree_inputs(const char* folder,
                                                                  const char* kind = "tree") {
  std::vector<std::pair<std::string, std::string>> inputs;
  for (const auto& entry : std::filesystem::directory_iterator(
           std::filesystem::path(PRIMSEG_FUZZ_DIR) / folder / kind)) {
    std::ifstream in(entry.path(), std::ios::binary);
    std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    inputs.emplace_back(entry.path().filename().string(), with_checksum(std::move(body)));
  }
  return inputs;
}

// Every seed is a valid tree, or the fuzzer would start from rejected inputs only.
TEST(TreeIo, TheFuzzersSeedsAreValidTrees) {
  const auto seeds = fuzz_tree_inputs("corpus");
  EXPECT_GE(seeds.size(), 5u);
  for (const auto& [name, image] : seeds) {
    SCOPED_TRACE(name);
    EXPECT_GT(deserialize_tree(image).face_count(), 1u);
  }
}

// Tree files the fuzzer once found accepted with content that broke cuts or reports (an infinite
// error curve, infinite report distances) are refused, naming the file and the merge.
TEST(TreeIo, TheFuzzersFindingsAreRefused) {
  const auto findings = fuzz_tree_inputs("regressions");
  EXPECT_GE(findings.size(), 2u);
  for (const auto& [name, image] : findings) {
    SCOPED_TRACE(name);
    expect_parse_error(image, "x.tree: invalid tree: merge");
  }
}

// Tree files the fuzzer found that are valid as files but whose primitives lie far from their
// clusters (a cube's planes over a mesh of subnormal coordinates): read, and every level's cluster
// reports are finite (fit_geometric scales its frame to the start primitive too).
TEST(TreeIo, TheFuzzersAcceptedFindingsGiveFiniteReports) {
  const auto findings = fuzz_tree_inputs("regressions", "tree-accepted");
  EXPECT_GE(findings.size(), 1u);
  for (const auto& [name, image] : findings) {
    SCOPED_TRACE(name);
    const Hierarchy hierarchy = deserialize_tree(image);
    for (std::uint32_t k = 1; k <= hierarchy.face_count(); ++k)
      for (const ClusterReport& report :
           describe_clusters(hierarchy, cut_by_count(hierarchy, k), DescribeOptions{})) {
        EXPECT_TRUE(std::isfinite(report.rms)) << k;
        EXPECT_TRUE(std::isfinite(report.max)) << k;
      }
  }
}

// What a pipe's first bytes tell: never more than the file has, the exact size once every count
// has arrived, and a refusal as soon as the data is no tree file.
TEST(TreeIo, ThePrefixOfATreeBoundsItsSize) {
  const std::string bytes = serialize_tree(sample_hierarchy());
  const std::uint64_t size = bytes.size();
  std::uint64_t previous = 0;
  bool exact = false;
  for (std::size_t length = 0; length <= bytes.size(); length += length < 600 ? 1 : 997) {
    SCOPED_TRACE(length);
    const TreeSizeBound bound = tree_size_from_prefix(std::string_view(bytes).substr(0, length));
    EXPECT_LE(bound.bytes, size);
    EXPECT_GE(bound.bytes, previous);  // more bytes, more known
    EXPECT_TRUE(bound.exact || !exact);
    if (bound.exact) {
      EXPECT_EQ(bound.bytes, size);
    }
    previous = bound.bytes;
    exact = bound.exact;
  }
  EXPECT_TRUE(exact);

  std::string foreign = bytes;
  foreign[3] = 'x';
  for (const std::size_t length : {4, 8, 100})
    EXPECT_THROW(tree_size_from_prefix(std::string_view(foreign).substr(0, length)), ParseError);
  EXPECT_NO_THROW(tree_size_from_prefix(std::string_view(foreign).substr(0, 3)));
  std::string newer = bytes;
  newer[8] = 2;
  EXPECT_THROW(tree_size_from_prefix(std::string_view(newer).substr(0, 20)), ParseError);
  // A vertex count of 2^63: the size saturates instead of wrapping around.
  std::string huge = bytes.substr(0, 8 + 4 + 3 + static_cast<unsigned char>(bytes[14]) + 48);
  huge += std::string(7, '\0') + '\x80';
  EXPECT_EQ(tree_size_from_prefix(huge).bytes, std::numeric_limits<std::uint64_t>::max());
}

// The tree of an input is the same, bit for bit, on every build: the floating-point contract
// (IEEE doubles, no contraction into FMA, no fast-math) leaves the compiler no freedom that could
// change a cost. CI runs this with g++ in Release and with clang++ under the sanitizers; builds
// with LTO and profile-guided optimisation gave the same trees too. (On x86-64 with glibc: the
// generated shapes call the C library's sin and cos.) A change that alters trees on purpose
// updates these (bench/compare_revisions.sh reports which levels moved).
TEST(TreeIo, TreesHaveTheSameChecksumOnEveryBuild) {
  const auto checksum = [](const Hierarchy& hierarchy) {
    const std::string bytes = serialize_tree(hierarchy);
    std::uint64_t value = 0;  // the file's last 8 bytes: FNV-1a 64 of all the others
    for (int i = 0; i < 8; ++i)
      value |= std::uint64_t{static_cast<unsigned char>(bytes[bytes.size() - 8 + i])} << (8 * i);
    return value;
  };
  struct Case {
    std::string name;
    std::function<Hierarchy()> build;
    std::uint64_t expected;
  };
  HierarchyOptions every_type;
  every_type.primitives = testing::every_primitive_type();
  every_type.weights = VertexWeights::Uniform;
  ShapeOptions noisy;
  noisy.noise = 0.002;
  noisy.seed = 5;
  const std::vector<Case> cases = {
      {"fandisk", [] { return build_hierarchy(read_mesh(testing::cgal_mesh("fandisk.off"))); },
       0x2026b6c97adfd56d},
      {"noise-free box_with_countersink (zero-cost ties)",
       [] { return build_hierarchy(make_shape("box_with_countersink").mesh); }, 0x845afa13e73a9a53},
      {"noisy filleted_cylinder, every type, uniform weights",
       [&] { return build_hierarchy(make_shape("filleted_cylinder", noisy).mesh, every_type); },
       0x4b0c31aaf46666be},
  };
  const auto hex = [](std::uint64_t value) {
    char text[32];
    std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(value));
    return std::string(text);
  };
  for (const Case& c : cases) EXPECT_EQ(hex(checksum(c.build())), hex(c.expected)) << c.name;
}

}  // namespace
}  // namespace primseg
