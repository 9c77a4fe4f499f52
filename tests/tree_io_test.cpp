// The tree file: a faithful, self-contained, checked copy of a hierarchy.
#include "primseg/tree_io.hpp"

#include <gtest/gtest.h>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
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

}  // namespace
}  // namespace primseg
