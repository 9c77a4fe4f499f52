#include <cstdio>
#include <memory>

#include "command.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_info.hpp"
#include "primseg/mesh_io.hpp"

namespace primseg::cli {

Command add_info_command(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto* info = app.add_subcommand("info", "Print counts and defects of a mesh");
  info->add_option("MESH", *path, "Input mesh")->required();

  return {info, [path] {
            const Mesh mesh = read_mesh(*path);
            const MeshInfo i = describe_mesh(mesh);
            std::printf("%s\n", path->c_str());
            std::printf("  vertices            %u (%u isolated)\n", i.vertices,
                        i.isolated_vertices);
            std::printf("  faces               %u (%u polygons), %u triangles\n", i.faces,
                        i.polygons, i.triangles);
            std::printf("  components          %u\n", i.components);
            std::printf("  boundary edges      %u\n", i.boundary_edges);
            std::printf("  non-manifold edges  %u\n", i.non_manifold_edges);
            std::printf("  degenerate triangles %u, duplicate triangles %u\n",
                        i.degenerate_triangles, i.duplicate_triangles);
            std::printf("  bounding box        [%g %g %g] - [%g %g %g], diagonal %g\n",
                        i.bbox_min[0], i.bbox_min[1], i.bbox_min[2], i.bbox_max[0], i.bbox_max[1],
                        i.bbox_max[2], i.bbox_diagonal);
            // Reported, not refused: info is where a user finds out why the others refuse.
            try {
              check_geometric_range(mesh);
            } catch (const InvalidInputError& error) {
              std::printf("  out of range        %s\n", error.what());
            }
          }};
}

}  // namespace primseg::cli
