#include "hierarchy_regions.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <span>
#include <type_traits>

#include "face_triangles.hpp"
#include "huge_pages.hpp"
#include "no_index.hpp"
#include "parallel.hpp"
#include "primseg/dual_graph.hpp"
#include "primseg/error.hpp"

namespace primseg::detail {
namespace {

void split(std::vector<std::uint32_t>::iterator begin, std::vector<std::uint32_t>::iterator end,
           unsigned count, const std::vector<std::array<double, 3>>& centroid,
           std::vector<std::vector<std::uint32_t>>& regions) {
  if (count <= 1) {
    regions.emplace_back(begin, end);
    std::sort(regions.back().begin(), regions.back().end());
    return;
  }
  std::array<double, 3> lo = centroid[*begin], hi = lo;
  for (auto it = begin; it != end; ++it)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], centroid[*it][a]);
      hi[a] = std::max(hi[a], centroid[*it][a]);
    }
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
  const unsigned first_count = count / 2;
  const auto middle = begin + (end - begin) * first_count / count;
  // Ties by face id: the same cut whatever the order the faces came in.
  std::nth_element(begin, middle, end, [&](std::uint32_t x, std::uint32_t y) {
    return centroid[x][axis] != centroid[y][axis] ? centroid[x][axis] < centroid[y][axis] : x < y;
  });
  split(begin, middle, first_count, centroid, regions);
  split(middle, end, count - first_count, centroid, regions);
}

}  // namespace

std::vector<std::vector<std::uint32_t>> split_into_regions(const Mesh& mesh, unsigned count) {
  const std::uint32_t f = mesh.face_count();
  std::vector<std::array<double, 3>> centroid;
  resize_huge(centroid, f);
  // Each face's first triangle: face_of_triangle is non-decreasing.
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint32_t face = mesh.face_of_triangle[t];
    if (t > 0 && mesh.face_of_triangle[t - 1] == face) continue;
    const Triangle& corners = mesh.triangles[t];
    for (int a = 0; a < 3; ++a)
      centroid[face][a] = (mesh.positions[corners[0]][a] + mesh.positions[corners[1]][a] +
                           mesh.positions[corners[2]][a]) /
                          3;
  }
  std::vector<std::uint32_t> faces;
  resize_huge(faces, f);
  std::iota(faces.begin(), faces.end(), 0u);
  std::vector<std::vector<std::uint32_t>> regions;
  split(faces.begin(), faces.end(), std::max(1u, std::min(count, f)), centroid, regions);
  return regions;
}

Mesh region_mesh(const Mesh& mesh, const std::vector<std::uint32_t>& first,
                 const std::vector<std::uint32_t>& faces) {
  std::vector<std::uint32_t> vertex;
  resize_huge(vertex, mesh.vertex_count());
  std::fill(vertex.begin(), vertex.end(), kNone);
  Mesh region;
  std::size_t polygon_corners = 0, triangles = 0;
  for (const std::uint32_t face : faces) {
    polygon_corners += mesh.polygon(face).size();
    triangles += first[face + 1] - first[face];
  }
  reserve_huge_to_fill(region.positions,
                       std::min<std::size_t>(mesh.vertex_count(), polygon_corners));
  reserve_huge_to_fill(region.polygon_offsets, faces.size() + 1);
  reserve_huge_to_fill(region.polygon_vertices, polygon_corners);
  reserve_huge_to_fill(region.triangles, triangles);
  reserve_huge_to_fill(region.face_of_triangle, triangles);
  auto renumbered = [&](std::uint32_t v) {
    if (vertex[v] == kNone) {
      vertex[v] = static_cast<std::uint32_t>(region.positions.size());
      region.positions.push_back(mesh.positions[v]);
    }
    return vertex[v];
  };
  for (std::uint32_t i = 0; i < faces.size(); ++i) {
    const std::uint32_t face = faces[i];
    for (const std::uint32_t v : mesh.polygon(face))
      region.polygon_vertices.push_back(renumbered(v));
    region.polygon_offsets.push_back(static_cast<std::uint32_t>(region.polygon_vertices.size()));
    for (std::uint32_t t = first[face]; t < first[face + 1]; ++t) {
      const Triangle& corners = mesh.triangles[t];
      region.triangles.push_back(
          {renumbered(corners[0]), renumbered(corners[1]), renumbered(corners[2])});
      region.face_of_triangle.push_back(i);
    }
  }
  return region;
}

std::uint64_t region_merges(const Mesh& mesh, const HierarchyOptions& options,
                            std::vector<Merge>& merges, const std::function<void()>& then) {
  const std::uint32_t f = mesh.face_count();
  const unsigned count = std::min<unsigned>(options.regions, f / kMinRegionFaces);
  if (count <= 1) return 0;
  const std::vector<std::vector<std::uint32_t>> regions = split_into_regions(mesh, count);
  const std::vector<std::uint32_t> first = first_triangles(mesh);

  // A region's merges in its node ids and working frame.
  static_assert(std::is_trivially_destructible_v<Merge>);  // (release_pages below)
  constexpr std::size_t kReleaseEvery = (std::size_t{2} << 20) / sizeof(Merge);
  struct Built {
    std::vector<Merge> merges;
    std::uint64_t evaluations = 0;
    int exponent = 0;  // of the region's working frame
  };
  std::vector<Built> built(regions.size());
  HierarchyOptions region_options = options;
  region_options.regions = 1;
  region_options.threads = 1;
  auto build_region = [&](std::size_t r, unsigned) {
    if (r == regions.size()) return then();
    const auto faces = static_cast<std::uint32_t>(regions[r].size());
    auto region = std::make_shared<const Mesh>(region_mesh(mesh, first, regions[r]));
    built[r].exponent = working_frame_for(*region).exponent;
    HierarchyBuilder builder(std::move(region), region_options);
    const std::uint32_t kept =
        std::min(builder.total_merge_count(),
                 faces - (faces + kRegionFacesPerCluster - 1) / kRegionFacesPerCluster);
    while (builder.merge_count() < kept && builder.step()) {
    }
    built[r].evaluations = builder.evaluation_count();
    // Taken, not copied: the builder's arrays go now, while another region may still be built.
    built[r].merges = builder.take_merges();
  };
  // A region can fail a check the whole mesh passes (every face of one region within 1e-32 of
  // each other, below the geometric range): the whole mesh is then merged in the exact order.
  try {
    parallel_for_threads(regions.size() + 1, thread_count(options.threads), build_region);
  } catch (const InvalidInputError&) {
    return 0;
  }

  // Costs and errors into the mesh's frame: lengths scale by a power of two, errors as weight ×
  // length² (weights are areas, or uniform).
  const int exponent = working_frame_for(mesh).exponent;
  const int power = options.weights == VertexWeights::Area ? 4 : 2;
  std::uint64_t evaluations = 0;
  std::size_t total = 0;
  for (Built& region : built) {
    for (Merge& m : region.merges) {
      m.cost = std::ldexp(m.cost, power * (region.exponent - exponent));
      m.error = std::ldexp(m.error, power * (region.exponent - exponent));
    }
    total += region.merges.size();
    evaluations += region.evaluations;
  }
  // Interleaved by cost (ties to the lower region), each region's in its own order: a level
  // then has about as many merges of each region as the exact order would make.
  const auto first_node = static_cast<std::uint32_t>(f + merges.size());
  std::vector<std::size_t> next(regions.size(), 0);
  std::vector<std::vector<std::uint32_t>> node_of(regions.size());  // region's merge → node
  for (std::size_t r = 0; r < regions.size(); ++r)
    reserve_huge_to_fill(node_of[r], built[r].merges.size());
  reserve_huge(merges, merges.size() + total);
  for (std::size_t done = 0; done < total; ++done) {
    std::size_t r = regions.size();
    for (std::size_t k = 0; k < regions.size(); ++k)
      if (next[k] < built[k].merges.size() &&
          (r == regions.size() || built[k].merges[next[k]].cost < built[r].merges[next[r]].cost))
        r = k;
    Merge m = built[r].merges[next[r]++];
    // The records read so far go back, 2 MB at a time, so that the tree's records are not held
    // twice. (The whole prefix each time: 2 MB of records need not hold an aligned huge page, and
    // pages already given back cost the call nothing.)
    if (next[r] % kReleaseEvery == 0)
      release_pages(built[r].merges.data(), next[r] * sizeof(Merge));
    const auto faces = static_cast<std::uint32_t>(regions[r].size());
    auto global = [&](std::uint32_t node) {
      return node < faces ? regions[r][node] : node_of[r][node - faces];
    };
    const std::uint32_t a = global(m.first), b = global(m.second);
    m.first = std::min(a, b);
    m.second = std::max(a, b);
    node_of[r].push_back(first_node + static_cast<std::uint32_t>(done));
    merges.push_back(m);
  }
  return evaluations;
}

bool merges_join_linked_clusters(const DualGraph& graph, std::span<const Merge> merges) {
  // The merges as a forest over the faces, union by size, each link stamped with its merge:
  // stamps grow towards the roots and the depth is O(log F). Two faces are first in one cluster
  // at the last stamp of the climb that meets them, always climbing the lower stamp.
  const std::uint32_t f = graph.face_count();
  std::vector<std::uint32_t> up, stamp, size, root_of_node;
  resize_huge(up, f);
  resize_huge(stamp, f);
  resize_huge(size, f);
  resize_huge(root_of_node, f + merges.size());
  std::iota(up.begin(), up.end(), 0u);
  std::fill(stamp.begin(), stamp.end(), kNone);
  std::fill(size.begin(), size.end(), 1u);
  std::iota(root_of_node.begin(), root_of_node.begin() + f, 0u);
  for (std::uint32_t i = 0; i < merges.size(); ++i) {
    std::uint32_t a = root_of_node[merges[i].first], b = root_of_node[merges[i].second];
    if (size[a] < size[b]) std::swap(a, b);
    up[b] = a;
    stamp[b] = i;
    size[a] += size[b];
    root_of_node[f + i] = a;
  }
  std::vector<bool> linked(merges.size(), false);
  for (const DualEdge& e : graph.edges()) {
    std::uint32_t u = e.first, v = e.second, joined = kNone;
    while (u != v) {
      if (stamp[u] > stamp[v]) std::swap(u, v);
      if (stamp[u] == kNone) break;  // two roots: never joined
      joined = stamp[u];
      u = up[u];
    }
    if (u == v && joined != kNone) linked[joined] = true;
  }
  return std::find(linked.begin(), linked.end(), false) == linked.end();
}

}  // namespace primseg::detail
