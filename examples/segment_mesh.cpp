// The library API in a few lines: read a mesh, build the hierarchy once, cut it at two levels.
// Usage: segment_mesh MESH [K]
#include <cstdio>
#include <cstdlib>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s MESH [K]\n", argv[0]);
    return 1;
  }
  try {
    const primseg::Mesh mesh = primseg::read_mesh(argv[1]);
    primseg::HierarchyOptions options;  // planes, cylinders and spheres; area weights
    const primseg::Hierarchy tree = primseg::build_hierarchy(mesh, options);

    // Any level, instantly: by number of clusters...
    const auto k = static_cast<std::uint32_t>(argc > 2 ? std::atoi(argv[2]) : 10);
    const primseg::Segmentation level = primseg::cut_by_count(tree, k);
    for (const primseg::ClusterReport& c : primseg::describe_clusters(tree, level))
      std::printf("cluster %u: %s, %u faces, rms %.3g, max %.3g\n", c.id,
                  std::string(primseg::to_string(c.primitive.type)).c_str(), c.face_count, c.rms,
                  c.max);
    // ... or by tolerance: the coarsest level whose clusters are within 0.5% of the diagonal.
    const double tolerance = 0.005 * primseg::bounding_box_diagonal(mesh);
    std::printf("%u clusters within %.3g\n",
                primseg::cut_by_tolerance(tree, tolerance).cluster_count(), tolerance);
  } catch (const primseg::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
