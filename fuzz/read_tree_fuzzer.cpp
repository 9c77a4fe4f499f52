// libFuzzer target for tree files (tree_io.hpp, docs/tree-format.md). The input is a tree file
// without its checksum: the checksum of the input is appended, so that mutations reach the checks
// behind it instead of all failing there. Checked:
// - deserialize_tree accepts the image or throws ParseError, never anything else;
// - a tree it accepts is one the engine can use as it uses its own: the invariants of
//   tree_invariants.hpp, every cut by count and a few by tolerance, the error curve, the automatic
//   level and the cluster reports (finite);
// - writing an accepted tree gives back the same bytes (the format has one spelling per tree);
// - tree_size_from_prefix, on every prefix of the image, throws nothing but ParseError and never
//   bounds the size above the image's when the image is a tree, and exactly once all has come.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "primseg/auto_level.hpp"
#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/tree_io.hpp"
#include "tree_invariants.hpp"

namespace {

using namespace primseg;

// FNV-1a, 64 bits, as docs/tree-format.md specifies the checksum.
std::uint64_t fnv1a(std::string_view bytes) {
  std::uint64_t hash = 14695981039346656037ull;
  for (const char c : bytes) {
    hash ^= static_cast<std::uint8_t>(c);
    hash *= 1099511628211ull;
  }
  return hash;
}

void use(const Hierarchy& hierarchy) {
  fuzz::check_tree(hierarchy);
  const std::uint32_t faces = hierarchy.face_count();
  for (std::uint32_t k = 1; k <= faces; ++k) fuzz::check_cut(hierarchy, cut_by_count(hierarchy, k));
  for (const double tolerance : {0.0, 1e-9, 0.01, 1.0, 1e300})
    fuzz::check_cut(hierarchy, cut_by_tolerance(hierarchy, tolerance));
  for (const ErrorCurvePoint& point : error_curve(hierarchy))
    if (!std::isfinite(point.rms) || point.rms < 0) fuzz::fail("error curve rms", point.rms);
  const AutoLevel level = choose_level(hierarchy);
  if (level.clusters < 1 || level.clusters > faces) fuzz::fail("automatic level", level.clusters);
  DescribeOptions describe;
  describe.threads = 1;
  for (const ClusterReport& report :
       describe_clusters(hierarchy, cut_by_count(hierarchy, level.clusters), describe))
    if (!std::isfinite(report.rms) || !std::isfinite(report.max) || !std::isfinite(report.area))
      fuzz::fail("cluster report", report.rms, report.max);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string image(reinterpret_cast<const char*>(data), size);
  const std::uint64_t checksum = fnv1a(image);
  for (int i = 0; i < 8; ++i) image.push_back(static_cast<char>(checksum >> (8 * i)));
  std::optional<Hierarchy> hierarchy;
  try {
    hierarchy.emplace(deserialize_tree({image.data(), image.size()}, "fuzz"));
  } catch (const ParseError&) {
  }
  // What a pipe's reader sees first: a few prefixes, and the whole image.
  for (const std::size_t length :
       {std::size_t{0}, std::size_t{9}, std::size_t{15}, image.size() / 2, image.size()}) {
    const std::string_view prefix = std::string_view(image).substr(0, length);
    TreeSizeBound bound;
    try {
      bound = tree_size_from_prefix(prefix, "fuzz");
    } catch (const ParseError&) {
      if (hierarchy) fuzz::fail("a prefix of a valid tree refused", double(length));
      continue;
    }
    if (hierarchy && (bound.bytes > image.size() ||
                      (length == image.size() && !(bound.exact && bound.bytes == image.size()))))
      fuzz::fail("size bound of a valid tree", double(bound.bytes), double(image.size()));
  }
  if (!hierarchy) return 0;
  use(*hierarchy);
  if (serialize_tree(*hierarchy) != image) fuzz::fail("written tree differs from the one read");
  return 0;
}
