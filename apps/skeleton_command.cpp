#include <array>
#include <cstdio>
#include <memory>

#include "../src/file_io.hpp"
#include "../src/skeleton_file.hpp"
#include "command.hpp"
#include "limits.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/skeleton.hpp"
#include "primseg/skeleton_gltf.hpp"
#include "primseg/skinning.hpp"
#include "skeleton_outputs.hpp"

namespace primseg::cli {

namespace {

struct SkeletonCommandOptions {
  std::string mesh_path, output, primitives = "cylinder";
  std::optional<std::string> skin_weights, gltf;
  std::uint32_t max_influences = GltfOptions{}.max_influences;
  SkeletonPicture picture;
  LevelChoice level;
  double band = SkinningOptions{}.band;
  std::string joints{to_string(SkeletonOptions{}.joints)};
  unsigned threads = 0, regions = 1;
  bool quiet = false;
  ResourceLimits limits;
};

// Runs `primseg skeleton` with its parsed options.
void run_skeleton(const SkeletonCommandOptions& o) {
  HierarchyOptions options;
  options.primitives = parse_primitives(o.primitives);
  options.threads = o.threads;
  options.regions = o.regions;
  validate(options);
  const SkeletonOptions skeleton_choice = skeleton_options(o.joints);
  const SkinningOptions skinning = skinning_options(o.band);
  auto mesh = std::make_shared<const Mesh>(
      read_geometry_within(o.mesh_path, o.limits, o.picture.png ? kPictureBytes : 0));
  validate_level(o.level, mesh->face_count());
  const auto build_start = Clock::now();
  HierarchyBuilder builder(mesh, options);
  const Hierarchy hierarchy = builder.finish(Progress("hierarchy", o.quiet));
  const double build_seconds = seconds_since(build_start);
  const auto skeleton_start = Clock::now();
  const Skeleton skeleton =
      extract_skeleton(hierarchy, cut(hierarchy, o.level).segmentation, skeleton_choice);
  const double skeleton_seconds = seconds_since(skeleton_start);

  nlohmann::json json;
  json["mesh"] = mesh_summary(o.mesh_path, hierarchy);
  json["primitives"] = o.primitives;
  json["joint_rule"] = o.joints;
  const std::optional<std::uint32_t> requested = parse_cluster_count(*o.level.clusters);
  if (requested)
    json["requested_clusters"] = *requested;
  else
    json["requested_clusters"] = "auto";
  json["timing"] = {{"hierarchy_seconds", build_seconds}, {"skeleton_seconds", skeleton_seconds}};
  if (o.skin_weights || o.gltf) {
    const auto skin_start = Clock::now();
    const SkinWeights weights = compute_skin_weights(*mesh, skeleton, skinning);
    json["timing"]["skin_weights_seconds"] = seconds_since(skin_start);
    if (o.skin_weights) detail::write_file_atomically(*o.skin_weights, skin_weights_text(weights));
    if (o.gltf) {
      GltfOptions gltf;
      gltf.max_influences = o.max_influences;
      detail::write_file_atomically(*o.gltf, skinned_glb(*mesh, skeleton, weights, gltf));
    }
  }
  detail::write_file_atomically(o.output, detail::skeleton_file_text(skeleton, std::move(json)));
  o.picture.write(*mesh, skeleton);
  if (!o.quiet) {
    std::size_t counts[3] = {0, 0, 0};
    for (const Joint& joint : skeleton.joints) ++counts[static_cast<int>(joint.kind)];
    std::printf("%s: %s, hierarchy in %.3f s; %s, %s (%zu sensitive, %zu locked, %zu virtual)\n",
                input_name(o.mesh_path).c_str(), count_of(mesh->face_count(), "face").c_str(),
                build_seconds, count_of(skeleton.cluster_count(), "bone").c_str(),
                count_of(skeleton.joints.size(), "joint").c_str(), counts[0], counts[1], counts[2]);
  }
}

}  // namespace

Command add_skeleton_command(CLI::App& app) {
  auto o = std::make_shared<SkeletonCommandOptions>();
  auto* command = app.add_subcommand(
      "skeleton", "Extract a deformation skeleton (one bone per cluster) from a level");
  command
      ->add_option("MESH", o->mesh_path, "Input mesh (.off .obj .ply .stl; - for standard input)")
      ->required();
  command
      ->add_option("--clusters", o->level.clusters, "Number of clusters K (1..F) or auto: of bones")
      ->required();
  command
      ->add_option("--primitives", o->primitives,
                   "Primitive types, comma-separated (cylinders only, as in the paper, by default)")
      ->capture_default_str();
  command->add_option("-o,--output", o->output, "Skeleton file (JSON)")->required();
  command->add_option("--skin-weights", o->skin_weights,
                      "Write skinning weights: one line per vertex, 'bone weight' pairs");
  auto* gltf_option =
      command->add_option("--gltf", o->gltf,
                          "Write the mesh skinned to the skeleton as binary glTF 2.0 (.glb), for "
                          "Blender, three.js or a game engine");
  command
      ->add_option("--max-influences", o->max_influences,
                   "--gltf: most bones per vertex, the largest weights kept and rescaled (0: all; "
                   "4 for engines that take four)")
      ->capture_default_str()
      ->needs(gltf_option);
  add_joints_option(*command, o->joints);
  command
      ->add_option("--band", o->band,
                   "Skinning blend half-width on each side of a boundary, in bone radii")
      ->capture_default_str();
  o->picture.add_options(*command, "the skeleton over the clusters");
  command->add_option("--threads", o->threads, "Threads (0: all cores)")->capture_default_str();
  add_regions_option(*command, o->regions);
  command->add_flag("--quiet,-q", o->quiet, "No summary or progress output");
  add_limit_options(*command, o->limits, kHierarchyBytesPerFace);

  return {command, [o] { run_skeleton(*o); }};
}

}  // namespace primseg::cli
