#include <cstdio>
#include <filesystem>
#include <memory>

#include "command.hpp"
#include "limits.hpp"
#include "primseg/mesh_io.hpp"

namespace primseg::cli {

Command add_segment_command(CLI::App& app) {
  struct Options {
    std::string mesh_path, primitives = "plane,cylinder,sphere", weights = "area";
    bool exact_costs = false, eager = false;
    unsigned threads = 0, regions = 1;
    double merge_batch_tolerance = 0;
    LevelOptions level;
    ResourceLimits limits;
  };
  auto o = std::make_shared<Options>();
  auto* segment = app.add_subcommand("segment", "Build the hierarchy of a mesh and report a level");
  segment
      ->add_option("MESH", o->mesh_path, "Input mesh (.off .obj .ply .stl; - for standard input)")
      ->required();
  add_level_options(*segment, o->level);
  add_fit_options(*segment, o->level);
  add_limit_options(*segment, o->limits, kHierarchyBytesPerFace);
  segment->add_option("--primitives", o->primitives, "Primitive types, comma-separated")
      ->capture_default_str();
  segment->add_option("--weights", o->weights, "Vertex weights of the fitting error")
      ->check(CLI::IsMember({"area", "uniform"}))
      ->capture_default_str();
  segment->add_option("--tree", o->level.files.tree, "Write the whole hierarchy");
  segment
      ->add_option("--threads", o->threads,
                   "Threads for the parallel parts (0: all cores); the tree does not depend "
                   "on it")
      ->capture_default_str();
  segment->add_flag(
      "--eager", o->eager,
      "Reference mode: evaluate every candidate at once (same tree as the default lazy mode)");
  add_merge_batch_option(*segment, o->merge_batch_tolerance);
  add_regions_option(*segment, o->regions);
  segment->add_flag("--exact-costs", o->exact_costs,
                    "Reference mode: exact Euclidean errors, O(cluster size) per candidate");

  return {
      segment, [o] {
        HierarchyOptions options;
        options.primitives = parse_primitives(o->primitives);
        options.weights = o->weights == "uniform" ? VertexWeights::Uniform : VertexWeights::Area;
        options.exact_costs = o->exact_costs;
        options.threads = o->threads;
        options.evaluation = o->eager ? CandidateEvaluation::Eager : CandidateEvaluation::Lazy;
        options.merge_batch_tolerance = o->merge_batch_tolerance;
        options.regions = o->regions;
        validate(options);
        validate_level_outputs(o->level);
        const auto read_start = Clock::now();
        auto mesh = std::make_shared<const Mesh>(
            read_geometry_within(o->mesh_path, o->limits, o->level.files.png ? kPictureBytes : 0));
        const double read_seconds = seconds_since(read_start);
        validate_level(o->level.level, mesh->face_count());
        const auto build_start = Clock::now();
        HierarchyBuilder builder(mesh, options);
        const Hierarchy hierarchy = builder.finish(Progress("hierarchy", o->level.quiet));
        const double build_seconds = seconds_since(build_start);
        nlohmann::json summary;
        summary["mesh"] = mesh_summary(o->mesh_path, hierarchy);
        summary["primitives"] = o->primitives;
        summary["weights"] = o->weights;
        summary["timing"] = {{"read_seconds", read_seconds}, {"hierarchy_seconds", build_seconds}};
        if (!o->level.quiet)
          std::printf("%s: %s, %s, hierarchy in %.3f s\n", input_name(o->mesh_path).c_str(),
                      count_of(mesh->face_count(), "face").c_str(),
                      count_of(hierarchy.component_count(), "component").c_str(), build_seconds);
        report_level(hierarchy, o->level, summary, Clock::now());
      }};
}

}  // namespace primseg::cli
