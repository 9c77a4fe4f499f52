#include <cstdio>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "limits.hpp"
#include "primseg/denoise.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_info.hpp"
#include "primseg/mesh_io.hpp"

namespace primseg::cli {

Command add_info_command(CLI::App& app) {
  struct Options {
    std::string path;
    std::optional<std::string> json;
    bool noise = false;
    ResourceLimits limits;
  };
  auto o = std::make_shared<Options>();
  auto* info = app.add_subcommand("info", "Print counts and defects of a mesh");
  info->add_option("MESH", o->path, "Input mesh (- for standard input)")->required();
  info->add_option("--json", o->json,
                   "Write the counts as JSON (- for standard output, instead of the text)");
  info->add_flag("--noise", o->noise,
                 "Also estimate the noise along the normals (what bilateral smoothing moves the "
                 "vertices, RMS; on coarse meshes curvature counts too), for --tolerance");
  add_limit_options(*info, o->limits, kMeshBytesPerFace);

  return {info, [o] {
            std::uint64_t file_bytes = 0;
            // The estimate smooths a copy of the mesh, with each face's neighbourhood.
            if (o->noise) o->limits.bytes_per_face = kNoiseEstimateBytesPerFace;
            const Mesh mesh = read_input_mesh(o->path, &file_bytes, o->limits.max_memory);
            check_mesh_limits({&mesh}, file_bytes, o->limits);
            const MeshInfo i = describe_mesh(mesh);
            // Reported, not refused: info is where a user finds out why the others refuse.
            std::optional<std::string> out_of_range;
            try {
              check_geometric_range(mesh);
            } catch (const InvalidInputError& error) {
              out_of_range = error.what();
            }
            // Not for coordinates out of range, which no fit takes either.
            std::optional<double> noise;
            if (o->noise && !out_of_range) noise = estimate_noise(mesh);
            if (o->json) {
              // The keys and values of the Python module's Mesh.info().
              nlohmann::json json = {
                  {"vertices", i.vertices},
                  {"isolated_vertices", i.isolated_vertices},
                  {"faces", i.faces},
                  {"polygons", i.polygons},
                  {"triangles", i.triangles},
                  {"components", i.components},
                  {"boundary_edges", i.boundary_edges},
                  {"non_manifold_edges", i.non_manifold_edges},
                  {"degenerate_triangles", i.degenerate_triangles},
                  {"duplicate_triangles", i.duplicate_triangles},
                  {"inconsistent_edges", i.inconsistent_edges},
                  {"inward_components", i.inward_components},
                  {"bbox_min", i.bbox_min},
                  {"bbox_max", i.bbox_max},
                  {"bbox_diagonal", i.bbox_diagonal},
                  {"out_of_range", out_of_range ? nlohmann::json(*out_of_range) : nullptr}};
              if (o->noise) json["noise_estimate"] = noise ? nlohmann::json(*noise) : nullptr;
              write_output(*o->json, json.dump(2) + "\n");
              if (*o->json == kStandardOutput) return;
            }
            std::printf("%s\n", input_name(o->path).c_str());
            std::printf("  vertices            %u (%u isolated)\n", i.vertices,
                        i.isolated_vertices);
            std::printf("  faces               %u (%u polygons), %u triangles\n", i.faces,
                        i.polygons, i.triangles);
            std::printf("  components          %u\n", i.components);
            std::printf("  boundary edges      %u\n", i.boundary_edges);
            std::printf("  non-manifold edges  %u\n", i.non_manifold_edges);
            std::printf("  degenerate triangles %u, duplicate triangles %u\n",
                        i.degenerate_triangles, i.duplicate_triangles);
            std::string orientation =
                i.inconsistent_edges == 0
                    ? std::string("consistent")
                    : "inconsistent across " + count_of(i.inconsistent_edges, "edge");
            if (i.inward_components > 0)
              orientation +=
                  ", " + count_of(i.inward_components, "closed component") + " facing inwards";
            std::printf("  orientation         %s\n", orientation.c_str());
            std::printf("  bounding box        [%g %g %g] - [%g %g %g], diagonal %g\n",
                        i.bbox_min[0], i.bbox_min[1], i.bbox_min[2], i.bbox_max[0], i.bbox_max[1],
                        i.bbox_max[2], i.bbox_diagonal);
            if (out_of_range) std::printf("  out of range        %s\n", out_of_range->c_str());
            if (noise)
              std::printf("  noise estimate      %g (%.3g%% of the diagonal)\n", *noise,
                          i.bbox_diagonal > 0 ? 100 * *noise / i.bbox_diagonal : 0.0);
          }};
}

}  // namespace primseg::cli
