#include <cmath>
#include <cstdio>
#include <memory>
#include <thread>

#include "command.hpp"
#include "limits.hpp"
#include "primseg/denoise.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"

namespace primseg::cli {

namespace {

struct DenoiseCommandOptions {
  std::string mesh_path, output_path, primitives = "plane,cylinder,sphere";
  int iterations = 1;
  int smoothing_steps = DenoiseOptions{}.smoothing_steps;
  bool stylize = false;
  bool bilateral = false;
  double max_move = DenoiseOptions{}.max_move_edge_lengths;
  double min_crease_angle = DenoiseOptions{}.min_crease_angle_degrees;
  int relabel_passes = DenoiseOptions{}.relabel_passes;
  double relation_significance = DenoiseOptions{}.relation_significance;
  std::optional<double> noise_factor;
  int ensemble_members = DenoiseOptions{}.ensemble_members;
  double ensemble_jitter = DenoiseOptions{}.ensemble_jitter;
  unsigned threads = 0, regions = 1;
  LevelOptions level;
  ResourceLimits limits;
};

// The library's options for the command's, checked.
DenoiseOptions denoise_options(const DenoiseCommandOptions& o) {
  DenoiseOptions options;
  options.mode = o.stylize ? SnapMode::NearestIncident : SnapMode::AllIncident;
  options.max_move_edge_lengths = o.max_move;
  options.smoothing_steps = o.smoothing_steps;
  if (o.bilateral) options.bilateral_smoothing = BilateralSmoothingOptions{};
  options.min_crease_angle_degrees = o.min_crease_angle;
  options.relabel_passes = o.relabel_passes;
  options.relation_significance = o.relation_significance;
  options.noise_tolerance_factor = o.noise_factor;
  options.ensemble_members = o.ensemble_members;
  options.ensemble_jitter = o.ensemble_jitter;
  options.hierarchy.primitives = parse_primitives(o.primitives);
  options.hierarchy.threads = o.threads;
  options.hierarchy.regions = o.regions;
  validate(options);
  return options;
}

// The level a round snaps onto: with --clusters auto, denoising's own automatic level (under
// noise, a multiple of the noise), else the cut the level options ask for.
ChosenLevel round_level(const Denoiser& denoiser, const Hierarchy& hierarchy,
                        const LevelChoice& choice, bool stylize) {
  if (!choice.clusters || parse_cluster_count(*choice.clusters)) return cut(hierarchy, choice);
  DenoiseLevel chosen = denoiser.automatic_level(hierarchy);
  ChosenLevel level{std::move(chosen.segmentation), std::move(chosen.automatic), std::nullopt};
  // Stylization keeps the segmentation's level and estimates no noise.
  if (!stylize)
    level.noise = {chosen.noise, chosen.tolerance, chosen.jump_worst_rms, chosen.by_noise};
  return level;
}

// A round's entry of the JSON's "rounds".
nlohmann::json round_json(const SnapReport& r) {
  return {{"clusters", r.clusters},
          {"boundary_vertices", r.boundary_vertices},
          {"snapped", r.snapped},
          {"moved", r.moved},
          {"fallbacks", r.fallbacks},
          {"blocked", r.blocked},
          {"mean_move", r.mean_move},
          {"max_move", r.max_move},
          {"ensemble_members", r.ensemble_members},
          {"reverted", r.reverted}};
}

// `diagonal`: the input's bounding-box diagonal, which the noise is given as a percentage of too.
void print_round(int round, const ChosenLevel& level, const SnapReport& r, double diagonal) {
  if (level.noise) {
    const ChosenLevel::Noise& noise = *level.noise;
    const bool jump = level.automatic->rule == AutoLevelRule::Jump;
    if (jump) {
      std::printf("round %d: the error curve jumps at %u clusters, the worst with RMS %.6g", round,
                  level.automatic->clusters, noise.jump_worst_rms);
      // A noise-free mesh can estimate no noise at all: its tolerance is 0.
      if (noise.tolerance > 0)
        std::printf(" (%.3g tolerances)", noise.jump_worst_rms / noise.tolerance);
      if (noise.level_by_noise)
        std::printf(": beyond %g noise tolerances, a surface left out\n",
                    kMaxJumpClusterRmsInTolerances);
      else
        std::printf(": kept\n");
    }
    std::printf("round %d: noise estimate %.6g (%.3g%% of the diagonal), tolerance %.6g%s\n", round,
                noise.estimate, diagonal > 0 ? 100 * noise.estimate / diagonal : 0.0,
                noise.tolerance,
                !noise.level_by_noise ? ""
                : jump                ? "; level by noise: the clusters within it"
                                      : "; no jump in the error curve, level by noise: the "
                                        "clusters within it");
  }
  std::printf(
      "round %d: %s, %s snapped (%u on cluster borders, %u onto fewer primitives), %u moved, %u "
      "blocked; mean move %.6g, max %.6g\n",
      round, count_of(r.clusters, "cluster").c_str(),
      count_of(r.snapped, "vertex", "vertices").c_str(), r.boundary_vertices, r.fallbacks, r.moved,
      r.blocked, r.mean_move, r.max_move);
  if (r.ensemble_members > 1)
    std::printf("round %d: the mean of %u snaps (one per hierarchy), %s put back to the first's\n",
                round, r.ensemble_members, count_of(r.reverted, "vertex", "vertices").c_str());
}

// Runs `primseg denoise` with its parsed options (quiet once an output goes to standard output).
void run_denoise(DenoiseCommandOptions& o) {
  const DenoiseOptions options = denoise_options(o);
  validate_level_outputs(o.level);
  mesh_format_from_path(o.output_path);  // an unknown extension fails before any work
  const auto start = Clock::now();
  // The ensemble builds two members' hierarchies side by side when it has two threads.
  const unsigned threads = o.threads > 0 ? o.threads : std::thread::hardware_concurrency();
  if (o.ensemble_members > 1 && threads > 1) o.limits.bytes_per_face = kDenoiseEnsembleBytesPerFace;
  Mesh mesh = read_geometry_within(o.mesh_path, o.limits, o.level.files.png ? kPictureBytes : 0);
  validate_level(o.level.level, mesh.face_count());
  const double diagonal = bounding_box_diagonal(mesh);
  Denoiser denoiser(std::move(mesh), options);
  std::unique_ptr<Hierarchy> hierarchy;
  ChosenLevel level;
  nlohmann::json rounds = nlohmann::json::array();
  for (int i = 0; i < o.iterations; ++i) {
    hierarchy =
        std::make_unique<Hierarchy>(build_hierarchy(denoiser.segmented_mesh(), options.hierarchy));
    level = round_level(denoiser, *hierarchy, o.level.level, o.stylize);
    const SnapReport report =
        denoiser.snap(*hierarchy, level.segmentation, [&](const Hierarchy& member) {
          return round_level(denoiser, member, o.level.level, o.stylize).segmentation;
        });
    rounds.push_back(round_json(report));
    if (!o.level.quiet) print_round(i + 1, level, report, diagonal);
  }
  write_mesh(o.output_path, denoiser.mesh());
  nlohmann::json summary;
  summary["mesh"] = mesh_summary(o.mesh_path, *hierarchy);
  summary["denoise"] = {{"output", o.output_path},
                        {"mode", o.stylize ? "stylize" : "denoise"},
                        {"segmented_copy", o.bilateral             ? "bilateral"
                                           : o.smoothing_steps > 0 ? "taubin"
                                                                   : "input"},
                        {"rounds", rounds}};
  summary["timing"] = {{"denoise_seconds", seconds_since(start)}};
  // The level outputs show the last round's snap: its clusters after relabelling, with the
  // primitives the vertices went onto, on the denoised mesh (whose borders are the recovered
  // feature lines). The error curve and the linkage are the last round's hierarchy's, built on
  // the segmented copy.
  const SnappedLevel& snapped = denoiser.snapped_level();
  summary["level"] =
      level_summary(o.level, level, static_cast<std::uint32_t>(snapped.clusters.size()));
  summary["level"]["hierarchy_clusters"] = level.segmentation.cluster_count();
  summary["relations"] = relations_json(snapped.relations);
  write_level_outputs(*hierarchy, denoiser.mesh(), snapped.labels, snapped.clusters, o.level.files,
                      summary);
  if (!o.level.quiet) print_summary(snapped.clusters, snapped.relations);
}

}  // namespace

Command add_denoise_command(CLI::App& app) {
  auto o = std::make_shared<DenoiseCommandOptions>();
  auto* denoise = app.add_subcommand(
      "denoise",
      "Snap every vertex onto the primitives of a level: denoising and sharp-edge recovery");
  denoise
      ->add_option("MESH", o->mesh_path, "Input mesh (.off .obj .ply .stl; - for standard input)")
      ->required();
  denoise->add_option("-o,--output", o->output_path, "Output mesh (same vertex and face order)")
      ->required();
  add_level_options(*denoise, o->level,
                    "a jump of the error curve whose clusters fit the noise, else the clusters "
                    "within a multiple of the estimated noise (--noise-factor)");
  denoise
      ->add_option("--iterations", o->iterations,
                   "Segment-and-snap rounds, each on the previous round's result")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  denoise
      ->add_option("--smooth", o->smoothing_steps,
                   "Taubin smoothing steps of the copy that is segmented (the vertices are "
                   "snapped from their own positions)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  denoise
      ->add_flag("--bilateral", o->bilateral,
                 "Segment a copy smoothed by bilateral normal filtering (keeps edges sharp; "
                 "for noisy CAD parts)")
      ->excludes("--smooth");
  denoise->add_flag("--stylize", o->stylize,
                    "Snap each vertex onto its own cluster's primitive only (a boundary vertex "
                    "onto the nearest incident one), for few clusters");
  denoise
      ->add_option("--max-move", o->max_move,
                   "Largest move of a vertex, in its mean incident edge lengths (not applied "
                   "with --stylize)")
      ->capture_default_str();
  denoise
      ->add_option("--min-crease-angle", o->min_crease_angle,
                   "Primitives meeting at a smaller angle (degrees) are averaged, not intersected")
      ->capture_default_str();
  denoise
      ->add_option("--relabel-passes", o->relabel_passes,
                   "Passes moving each face to the neighbouring cluster whose refitted primitive "
                   "its corners are nearest to, before snapping (0: keep the hierarchy's labels)")
      ->check(CLI::Range(0, 100))
      ->capture_default_str();
  denoise
      ->add_option("--relation-significance", o->relation_significance,
                   "Relations the fits agree with within this many standard deviations are made "
                   "exact before snapping: parallel plane normals and cylinder axes, coaxial "
                   "cylinders (0: off)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  denoise->add_option("--noise-factor", o->noise_factor,
                      "With --clusters auto and no jump in the error curve (or one whose clusters "
                      "fit more than 4.5 times worse): clusters within this multiple of the "
                      "estimated noise (default: 1.2, 0.8 with --smooth, 0.4 with --bilateral)");
  denoise
      ->add_option("--ensemble", o->ensemble_members,
                   "Average the snaps onto this many hierarchies, each further one built on a "
                   "copy jittered by --ensemble-jitter: closer to the clean surface (16: "
                   "fandisk with 0.3% noise 4.3x -> 5.3x lower RMS), a hierarchy per member (two "
                   "built at once on two threads)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  denoise
      ->add_option("--ensemble-jitter", o->ensemble_jitter,
                   "Jitter of the ensemble's further copies, in estimated noise deviations "
                   "(added before smoothing)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  denoise->add_option("--primitives", o->primitives, "Primitive types, comma-separated")
      ->capture_default_str();
  denoise->add_option("--threads", o->threads, "Threads for the hierarchy (0: all cores)")
      ->capture_default_str();
  add_regions_option(*denoise, o->regions);
  add_limit_options(*denoise, o->limits, kDenoiseBytesPerFace);

  return {denoise, [o] { run_denoise(*o); }};
}

}  // namespace primseg::cli
