// primseg: hierarchical segmentation of meshes into fitting primitives (command-line tool).
//
// Exit codes: 0 success, 1 bad input or usage (with a message on stderr), 2 internal error.

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <new>
#include <string>

#include "level.hpp"
#include "outputs.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_info.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/primitives/primitive_fitter.hpp"
#include "primseg/tree_io.hpp"

namespace primseg::cli {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::vector<PrimitiveType> parse_primitives(const std::string& list) {
  std::vector<PrimitiveType> types;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    const std::string name = list.substr(begin, end - begin);
    const auto type = primitive_type_from_string(name);
    if (!type || !has_fitter(*type)) {
      std::string known;
      for (int t = 0; t < kPrimitiveTypeCount; ++t)
        if (has_fitter(static_cast<PrimitiveType>(t)))
          known +=
              (known.empty() ? "" : ", ") + std::string(to_string(static_cast<PrimitiveType>(t)));
      throw InvalidInputError("--primitives: unknown primitive '" + name +
                              "' (available: " + known + ")");
    }
    types.push_back(*type);
    begin = end + 1;
  }
  return types;
}

// A one-line progress indicator on stderr, only when stderr is a terminal.
class Progress {
 public:
  Progress(const char* what, bool quiet) : what_(what), enabled_(!quiet && ::isatty(2)) {}
  void operator()(double fraction) const {
    if (enabled_) std::fprintf(stderr, "\r%s: %3d%%", what_, static_cast<int>(fraction * 100));
    if (enabled_ && fraction >= 1) std::fprintf(stderr, "\n");
  }

 private:
  const char* what_;
  bool enabled_;
};

nlohmann::json mesh_summary(const std::string& file, const Hierarchy& hierarchy) {
  const Mesh& mesh = hierarchy.mesh();
  return {{"file", file},
          {"vertices", mesh.vertex_count()},
          {"faces", mesh.face_count()},
          {"triangles", mesh.triangle_count()},
          {"components", hierarchy.component_count()},
          {"bbox_diagonal", bounding_box_diagonal(mesh)}};
}

struct LevelOptions {
  LevelChoice level;
  OutputFiles files;
  bool quiet = false;
};

void add_level_options(CLI::App& command, LevelOptions& options) {
  auto* clusters =
      command.add_option("--clusters", options.level.clusters, "Number of clusters K (1..F)");
  auto* tolerance = command.add_option(
      "--tolerance", options.level.tolerance,
      std::string("Largest RMS distance of a cluster to its primitive, in input units or T% of "
                  "the bounding-box diagonal (default ") +
          kDefaultTolerance + ")");
  clusters->excludes(tolerance);
  command.add_option("--labels", options.files.labels, "Write one cluster label per input face");
  command.add_option("--json", options.files.json, "Write clusters and primitives as JSON");
  command.add_option("--colored", options.files.colored,
                     "Write the mesh coloured by cluster (.ply colours or .obj groups)");
  command.add_option("--png", options.files.png,
                     "Render the clusters to a PNG picture (800x600, three-quarter view)");
  command.add_option("--linkage", options.files.linkage,
                     "Write the whole tree as a SciPy linkage matrix (text: a b cost size per "
                     "merge, numpy.loadtxt)");
  command.add_flag("--quiet,-q", options.quiet, "No summary or progress output");
}

void report_level(const Hierarchy& hierarchy, const LevelOptions& options, nlohmann::json summary,
                  Clock::time_point cut_start) {
  const Segmentation segmentation = cut(hierarchy, options.level);
  const std::vector<ClusterReport> reports = describe_clusters(hierarchy, segmentation);
  summary["timing"]["cut_seconds"] = seconds_since(cut_start);
  summary["level"] = {{"clusters", segmentation.cluster_count()}};
  if (options.level.clusters)
    summary["level"]["requested_clusters"] = *options.level.clusters;
  else
    summary["level"]["tolerance"] = options.level.tolerance.value_or(kDefaultTolerance);
  write_level_outputs(hierarchy, segmentation, reports, options.files, summary);
  if (options.files.tree) write_tree(*options.files.tree, hierarchy);
  if (!options.quiet) print_summary(reports);
}

int run(int argc, char** argv) {
  CLI::App app{
      "primseg: hierarchical segmentation of triangle meshes into planes, spheres and "
      "cylinders"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "primseg 0.1.0");

  // segment
  std::string mesh_path, primitives = "plane,cylinder,sphere", weights = "area";
  bool exact_costs = false;
  unsigned threads = 0;
  LevelOptions segment_options;
  auto* segment = app.add_subcommand("segment", "Build the hierarchy of a mesh and report a level");
  segment->add_option("MESH", mesh_path, "Input mesh (.off .obj .ply .stl)")->required();
  add_level_options(*segment, segment_options);
  segment->add_option("--primitives", primitives, "Primitive types, comma-separated")
      ->capture_default_str();
  segment->add_option("--weights", weights, "Vertex weights of the fitting error")
      ->check(CLI::IsMember({"area", "uniform"}))
      ->capture_default_str();
  segment->add_option("--tree", segment_options.files.tree, "Write the whole hierarchy");
  segment
      ->add_option("--threads", threads,
                   "Threads for the parallel parts (0: all cores); the tree does not depend "
                   "on it")
      ->capture_default_str();
  segment->add_flag("--exact-costs", exact_costs,
                    "Reference mode: exact Euclidean errors, O(cluster size) per candidate");

  // cut
  std::string tree_path;
  LevelOptions cut_options;
  auto* cut_command = app.add_subcommand("cut", "Report a level of a saved hierarchy");
  cut_command->add_option("TREE", tree_path, "Tree file written by segment --tree")->required();
  add_level_options(*cut_command, cut_options);

  // info
  std::string info_path;
  auto* info = app.add_subcommand("info", "Print counts and defects of a mesh");
  info->add_option("MESH", info_path, "Input mesh")->required();

  // Name an unknown command instead of CLI11's "A subcommand is required".
  if (argc > 1 && argv[1][0] != '-') {
    std::string known;
    bool found = false;
    for (const CLI::App* command : app.get_subcommands([](CLI::App*) { return true; })) {
      known += (known.empty() ? "" : ", ") + command->get_name();
      found |= command->get_name() == argv[1];
    }
    if (!found)
      throw InvalidInputError("unknown command '" + std::string(argv[1]) + "' (commands: " + known +
                              ")");
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 1;
  }

  if (*segment) {
    HierarchyOptions options;
    options.primitives = parse_primitives(primitives);
    options.weights = weights == "uniform" ? VertexWeights::Uniform : VertexWeights::Area;
    options.exact_costs = exact_costs;
    options.threads = threads;
    validate(options);
    validate_output_files(segment_options.files);
    const auto read_start = Clock::now();
    auto mesh = std::make_shared<const Mesh>(read_mesh(mesh_path));
    const double read_seconds = seconds_since(read_start);
    validate_level(segment_options.level, mesh->face_count());
    const auto build_start = Clock::now();
    HierarchyBuilder builder(mesh, options);
    const Hierarchy hierarchy = builder.finish(Progress("hierarchy", segment_options.quiet));
    const double build_seconds = seconds_since(build_start);
    nlohmann::json summary;
    summary["mesh"] = mesh_summary(mesh_path, hierarchy);
    summary["primitives"] = primitives;
    summary["weights"] = weights;
    summary["timing"] = {{"read_seconds", read_seconds}, {"hierarchy_seconds", build_seconds}};
    if (!segment_options.quiet)
      std::printf("%s: %u faces, %u components, hierarchy in %.3f s\n", mesh_path.c_str(),
                  mesh->face_count(), hierarchy.component_count(), build_seconds);
    report_level(hierarchy, segment_options, summary, Clock::now());
  } else if (*cut_command) {
    if (!cut_options.level.clusters && !cut_options.level.tolerance)
      throw InvalidInputError("cut: give the level with --clusters K or --tolerance T");
    validate_output_files(cut_options.files);
    const auto read_start = Clock::now();
    const Hierarchy hierarchy = read_tree(tree_path);
    validate_level(cut_options.level, hierarchy.face_count());
    nlohmann::json summary;
    summary["mesh"] = mesh_summary(tree_path, hierarchy);
    summary["timing"] = {{"read_seconds", seconds_since(read_start)}};
    report_level(hierarchy, cut_options, summary, Clock::now());
  } else if (*info) {
    const MeshInfo i = describe_mesh(read_mesh(info_path));
    std::printf("%s\n", info_path.c_str());
    std::printf("  vertices            %u (%u isolated)\n", i.vertices, i.isolated_vertices);
    std::printf("  faces               %u (%u polygons), %u triangles\n", i.faces, i.polygons,
                i.triangles);
    std::printf("  components          %u\n", i.components);
    std::printf("  boundary edges      %u\n", i.boundary_edges);
    std::printf("  non-manifold edges  %u\n", i.non_manifold_edges);
    std::printf("  degenerate triangles %u, duplicate triangles %u\n", i.degenerate_triangles,
                i.duplicate_triangles);
    std::printf("  bounding box        [%g %g %g] - [%g %g %g], diagonal %g\n", i.bbox_min[0],
                i.bbox_min[1], i.bbox_min[2], i.bbox_max[0], i.bbox_max[1], i.bbox_max[2],
                i.bbox_diagonal);
  }
  return 0;
}

}  // namespace
}  // namespace primseg::cli

int main(int argc, char** argv) {
  try {
    return primseg::cli::run(argc, argv);
  } catch (const primseg::Error& e) {
    std::fprintf(stderr, "primseg: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "primseg: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "primseg: internal error: %s\n", e.what());
    return 2;
  }
}
