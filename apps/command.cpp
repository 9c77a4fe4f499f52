#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <span>

#include "../src/file_io.hpp"
#include "../src/length_text.hpp"
#include "command.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/primitives/primitive_fitter.hpp"
#include "primseg/refine.hpp"
#include "primseg/tree_io.hpp"

namespace primseg::cli {

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string input_name(const std::filesystem::path& path) {
  return is_standard_input(path) ? std::string("standard input") : path.string();
}

namespace {

detail::ReadLimits memory_limits(std::optional<std::uint64_t> max_memory) {
  detail::ReadLimits limits;
  if (max_memory) {
    limits.max_bytes = *max_memory;
    limits.limit_name = "--max-memory";
  }
  return limits;
}

}  // namespace

Mesh read_input_mesh(const std::filesystem::path& path, std::uint64_t* bytes,
                     std::optional<std::uint64_t> max_memory) {
  const bool standard_input = is_standard_input(path);
  // As read_mesh(path): an unknown extension fails before the file is read.
  const std::optional<MeshFormat> format =
      standard_input ? std::nullopt : std::optional(mesh_format_from_path(path));
  const std::string name = input_name(path);
  detail::ReadLimits limits = memory_limits(max_memory);
  if (standard_input)
    limits.check_prefix = [&name](std::span<const char> prefix, std::uint64_t most_bytes) {
      // Data that could be a mesh only if it were larger than can be read is no mesh here either.
      // Throws the error the whole input would get.
      if (mesh_format_ruled_out(prefix, most_bytes)) read_mesh_detecting_format(prefix, name);
    };
  const detail::FileImage image =
      standard_input ? detail::read_standard_input(limits) : detail::read_file(path, limits);
  if (bytes) *bytes = image.size;
  const std::span<const char> content(image.bytes.get(), image.size);
  return format ? read_mesh(content, *format, name) : read_mesh_detecting_format(content, name);
}

Mesh read_geometry(const std::filesystem::path& path, std::uint64_t* bytes,
                   std::optional<std::uint64_t> max_memory) {
  Mesh mesh = read_input_mesh(path, bytes, max_memory);
  try {
    check_geometric_range(mesh);
  } catch (const InvalidInputError& error) {
    throw InvalidInputError(input_name(path) + ": " + error.what());
  }
  return mesh;
}

Hierarchy read_input_tree(const std::filesystem::path& path, std::uint64_t* bytes,
                          std::optional<std::uint64_t> max_memory) {
  const bool standard_input = is_standard_input(path);
  const std::string name = input_name(path);
  detail::ReadLimits limits = memory_limits(max_memory);
  // Cutting a tree takes about 3.3 times its file's bytes (512 per face against 154).
  limits.unsized_memory_fraction = 1.0 / 2;
  if (standard_input)
    limits.check_prefix = [&](std::span<const char> prefix, std::uint64_t most_bytes) {
      // Stop as soon as the data cannot be a tree that fits: a pipe may never end.
      const TreeSizeBound size = tree_size_from_prefix(prefix, name);
      if (size.bytes > most_bytes)
        throw InvalidInputError(
            name + ": the tree's counts declare " + std::to_string(size.bytes) +
            " bytes, more than " +
            (max_memory ? "--max-memory " + std::to_string(*max_memory)
                        : std::to_string(most_bytes) + " bytes, the most this read accepts"));
      if (size.exact && prefix.size() > size.bytes)
        throw ParseError(name + ": byte " + std::to_string(size.bytes) +
                         ": unexpected data after the tree's checksum");
    };
  const detail::FileImage image =
      standard_input ? detail::read_standard_input(limits) : detail::read_file(path, limits);
  if (bytes) *bytes = image.size;
  return deserialize_tree({image.bytes.get(), image.size}, name);
}

std::vector<std::string> split_comma_list(const std::string& list) {
  std::vector<std::string> items;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    items.push_back(list.substr(begin, end - begin));
    begin = end + 1;
  }
  return items;
}

std::vector<PrimitiveType> parse_primitives(const std::string& list) {
  try {
    return fittable_types_from_list(list);
  } catch (const InvalidInputError& error) {
    throw InvalidInputError(std::string("--primitives: ") + error.what());
  }
}

Progress::Progress(const char* what, bool quiet) : what_(what), enabled_(!quiet && ::isatty(2)) {}

void Progress::operator()(double fraction) const {
  if (enabled_) std::fprintf(stderr, "\r%s: %3d%%", what_, static_cast<int>(fraction * 100));
  if (enabled_ && fraction >= 1) std::fprintf(stderr, "\n");
}

nlohmann::json mesh_summary(const std::string& file, const Hierarchy& hierarchy) {
  const Mesh& mesh = hierarchy.mesh();
  return {{"file", file},
          {"vertices", mesh.vertex_count()},
          {"faces", mesh.face_count()},
          {"triangles", mesh.triangle_count()},
          {"components", hierarchy.component_count()},
          {"bbox_diagonal", bounding_box_diagonal(mesh)}};
}

void add_level_options(CLI::App& command, LevelOptions& options, std::string_view auto_level) {
  auto* clusters =
      command.add_option("--clusters", options.level.clusters,
                         "Number of clusters K (1..F), or 'auto': " + std::string(auto_level) +
                             " (rule, candidates and scores in the JSON)");
  auto* tolerance = command.add_option(
      "--tolerance", options.level.tolerance,
      std::string("Largest RMS distance of a cluster to its primitive, in input units or T% of "
                  "the bounding-box diagonal (default ") +
          kDefaultTolerance + ")");
  clusters->excludes(tolerance);
  command.add_option("--labels", options.files.labels,
                     "Write one cluster label per input face (- for standard output)");
  command.add_option("--json", options.files.json,
                     "Write clusters and primitives, and the borders where clusters meet, as JSON "
                     "(- for standard output)");
  command.add_option("--borders", options.files.borders,
                     "Write the borders where clusters meet as OBJ polylines (.obj; one object "
                     "border_A_B per pair of clusters)");
  command.add_option("--colored", options.files.colored,
                     "Write the mesh coloured by cluster (.ply colours or .obj groups)");
  command.add_option("--curve", options.files.curve,
                     "Write the error curve as CSV: k,rms for every number of clusters k (rms: "
                     "input units; - for standard output)");
  command.add_option("--png", options.files.png,
                     "Render the clusters to a PNG picture (800x600, three-quarter view)");
  command.add_option("--linkage", options.files.linkage,
                     "Write the whole tree as a SciPy linkage matrix (text: a b cost size per "
                     "merge, numpy.loadtxt; - for standard output)");
  command.add_flag("--quiet,-q", options.quiet, "No summary or progress output");
}

void add_merge_batch_option(CLI::App& command, double& tolerance) {
  command
      .add_option("--merge-batch-tolerance", tolerance,
                  "Approximate, faster merge order (0: the exact greedy order): merges within "
                  "(1 + T) times the cheapest are applied in a batch, their clusters' candidates "
                  "evaluated once at its end; 0.1 is a good start")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
}

void add_regions_option(CLI::App& command, unsigned& regions) {
  command
      .add_option("--regions", regions,
                  "Approximate, faster on several cores (1: the exact greedy order): the mesh "
                  "is cut into N regions merged side by side until each has a 32nd of its "
                  "faces as clusters, then the exact order goes on over the whole mesh; 2 on "
                  "two cores")
      ->check(CLI::Range(1u, 256u))
      ->capture_default_str();
}

void add_fit_options(CLI::App& command, LevelOptions& options) {
  command
      .add_option("--refine", options.refine,
                  "Boundary refinement passes after the cut: border faces move to the adjacent "
                  "cluster whose primitive fits them better (0: none)")
      ->check(CLI::Range(0u, 1000u))
      ->capture_default_str();
  command.add_flag("--regularize", options.regularize,
                   "Make the fits' design intent exact: plane normals and cylinder axes that "
                   "agree within their uncertainty share one direction, directions at right "
                   "angles become orthogonal, fragments of one face share one plane, cylinders "
                   "share one axis line and spheres are centred on it, spheres of one centre "
                   "share it, cylinders and spheres share one radius, and fillets become tangent "
                   "to the faces and parallel cylinders they border (listed as \"relations\" in "
                   "the JSON)");
  add_relation_options(command, options.relations);
}

namespace {

// Accepts a finite number above `low` (or equal to it, when `with_low`) and, when given, below
// `high`; otherwise the error names the range (CLI11 prefixes the option's name), as `range` says
// it. The help shows the interval.
CLI::Validator number_range(double low, std::optional<double> high, const std::string& range,
                            bool with_low = false) {
  const std::string from = (with_low ? "[" : "(") + CLI::detail::to_string(low);
  const std::string interval = high ? "in " + from + ", " + CLI::detail::to_string(*high) + ")"
                                    : (with_low ? ">= " : "> ") + CLI::detail::to_string(low);
  return CLI::Validator(
      [=](const std::string& text) -> std::string {
        double value = 0;
        const char* end = text.data() + text.size();
        const auto [stop, error] = std::from_chars(text.data(), end, value);
        const bool number = error == std::errc() && stop == end && std::isfinite(value);
        if (number && (value > low || (with_low && value == low)) && (!high || value < *high))
          return {};
        return "the value " + text + " must be " + range;
      },
      interval);
}

}  // namespace

RelationOptions RelationChoice::for_mesh(const Mesh& mesh) const {
  RelationOptions resolved = options;
  resolved.length_tolerance = detail::parse_length(length_tolerance, bounding_box_diagonal(mesh),
                                                   "--relation-length-tolerance");
  return resolved;
}

void add_relation_options(CLI::App& command, RelationChoice& choice) {
  RelationOptions& options = choice.options;
  command
      .add_option("--relation-significance", options.significance,
                  "--regularize: directions, axis lines and radii agree when they are within "
                  "this many standard deviations of their fits (> 0; larger finds more)")
      ->check(number_range(0, std::nullopt, "a positive number of standard deviations"))
      ->capture_default_str();
  command
      .add_option("--max-relation-angle", options.max_angle_degrees,
                  "--regularize: directions never agree, nor are made orthogonal, beyond this "
                  "angle, whatever their uncertainty (degrees, in (0, 90))")
      ->check(number_range(0, 90, "an angle in (0, 90) degrees"))
      ->capture_default_str();
  command
      .add_option("--relation-angle-tolerance", options.angle_tolerance_degrees,
                  "--regularize: directions within this angle of one another are parallel, and "
                  "within it of a right angle orthogonal, whatever their uncertainty (degrees, "
                  "at least 0 and below --max-relation-angle; 0: the significance alone). For "
                  "CAD parts, whose tessellation errs by more than its fits' statistics allow")
      ->check(number_range(0, 90, "an angle in [0, 90) degrees", true))
      ->capture_default_str();
  command
      .add_option("--relation-length-tolerance", choice.length_tolerance,
                  "--regularize: axis lines, plane offsets, sphere centres on lines, radii and "
                  "tangency gaps within this distance agree whatever their uncertainty, and a "
                  "joint fit that raises a member's RMS residual by at most this much (in "
                  "quadrature) keeps it (input units, or L% of the bounding-box diagonal; >= 0; "
                  "0: the significance alone)")
      ->check(detail::length_syntax_error, "L or L%")
      ->capture_default_str();
  command
      .add_option("--max-radius-difference", options.max_radius_difference,
                  "--regularize: radii never agree when they differ by more than this fraction "
                  "of the larger, nor does a radius known less well; nor is a sphere centred on "
                  "an axis farther than this fraction of its radius from it, or known less well, "
                  "nor a cylinder made tangent to a plane (a parallel cylinder) when its axis's "
                  "distance from it differs from its radius (their radii's sum or difference) by "
                  "more, or when the tangent refit moves its radius by more (in (0, 1); lower it "
                  "for fewer chance relations on freeform parts)")
      ->check(number_range(0, 1, "a fraction in (0, 1) of the larger radius"))
      ->capture_default_str();
}

void validate_relation_options(const RelationChoice& choice) {
  RelationOptions options = choice.options;
  options.length_tolerance =
      detail::parse_length(choice.length_tolerance, 1, "--relation-length-tolerance");
  if (!(options.angle_tolerance_degrees < options.max_angle_degrees))
    throw InvalidInputError("--relation-angle-tolerance " +
                            CLI::detail::to_string(options.angle_tolerance_degrees) +
                            " must be below --max-relation-angle (" +
                            CLI::detail::to_string(options.max_angle_degrees) + ")");
  validate(options);
}

std::string relation_options_signature(const RelationChoice& choice) {
  const RelationOptions& options = choice.options;
  const RelationOptions defaults;
  std::string signature;
  // Round-trip digits: options that differ only beyond a fixed number of decimals still differ.
  auto add = [&](const char* name, double value, double default_value) {
    if (value != default_value)
      signature += std::string(" ") + name + "=" + nlohmann::json(value).dump();
  };
  add("relation_significance", options.significance, defaults.significance);
  add("max_relation_angle", options.max_angle_degrees, defaults.max_angle_degrees);
  add("relation_angle_tolerance", options.angle_tolerance_degrees,
      defaults.angle_tolerance_degrees);
  // A length as a number, as before percentages were accepted: earlier outputs still resume.
  if (detail::is_percentage(choice.length_tolerance))
    signature += " relation_length_tolerance=" + nlohmann::json(choice.length_tolerance).dump();
  else
    add("relation_length_tolerance",
        detail::parse_length(choice.length_tolerance, 1, "--relation-length-tolerance"),
        defaults.length_tolerance);
  add("max_radius_difference", options.max_radius_difference, defaults.max_radius_difference);
  return signature;
}

void validate_level_outputs(LevelOptions& options) {
  validate_relation_options(options.relations);
  validate_output_files(options.files);
  if (writes_to_standard_output(options.files)) options.quiet = true;
}

namespace {

// The console's line on how --clusters auto chose the level.
void print_automatic_level(const AutoLevel& level) {
  switch (level.rule) {
    case AutoLevelRule::Jump: {
      LevelCandidate chosen;
      for (const LevelCandidate& c : level.candidates)
        if (c.clusters == level.clusters) chosen = c;
      if (chosen.score >= AutoLevelOptions{}.min_score)
        std::printf("automatic level: %u clusters, where the error curve jumps (score %.3g)\n",
                    level.clusters, chosen.score);
      else
        std::printf(
            "automatic level: %u clusters, where the next merge makes a cluster %.3g times the "
            "level's RMS (score %.3g)\n",
            level.clusters, chosen.merge_score, chosen.score);
      break;
    }
    case AutoLevelRule::Knee:
      std::printf("automatic level: %u clusters, the knee of the error curve (no jump)\n",
                  level.clusters);
      break;
    case AutoLevelRule::Components:
      std::printf("automatic level: one cluster per component (no jump)\n");
      break;
  }
}

}  // namespace

void report_level(const Hierarchy& hierarchy, const LevelOptions& options, nlohmann::json summary,
                  Clock::time_point cut_start) {
  report_level(hierarchy, options, cut(hierarchy, options.level), std::move(summary), cut_start);
}

void report_level(const Hierarchy& hierarchy, const LevelOptions& options, ChosenLevel level,
                  nlohmann::json summary, Clock::time_point cut_start) {
  Segmentation& segmentation = level.segmentation;
  std::vector<ClusterReport> reports;
  nlohmann::json refinement;
  if (options.refine > 0) {
    const auto refine_start = Clock::now();
    BoundaryRefinementOptions refine_options;
    refine_options.max_passes = options.refine;
    RefinedLevel refined = refine_boundaries(hierarchy, segmentation, refine_options);
    segmentation = std::move(refined.segmentation);
    reports = std::move(refined.reports);
    refinement = {{"max_passes", options.refine},
                  {"passes", refined.passes},
                  {"moved_faces", refined.moved_faces}};
    summary["timing"]["refine_seconds"] = seconds_since(refine_start);
  } else {
    reports = describe_clusters(hierarchy, segmentation);
  }
  std::vector<ClusterRelation> relations;
  if (options.regularize) {
    relations = regularize_clusters(hierarchy, segmentation, reports,
                                    options.relations.for_mesh(hierarchy.mesh()));
    summary["relations"] = relations_json(relations);
  }
  summary["timing"]["cut_seconds"] = seconds_since(cut_start);
  summary["level"] = level_summary(options, level, segmentation.cluster_count());
  if (!refinement.is_null()) summary["level"]["refinement"] = std::move(refinement);
  write_level_outputs(hierarchy, hierarchy.mesh(), segmentation.labels, reports, options.files,
                      summary);
  if (options.files.tree) write_output(*options.files.tree, serialize_tree(hierarchy));
  if (!options.quiet) {
    if (level.automatic) print_automatic_level(*level.automatic);
    print_summary(reports, relations);
  }
}

nlohmann::json level_summary(const LevelOptions& options, const ChosenLevel& level,
                             std::uint32_t clusters) {
  nlohmann::json summary = {{"clusters", clusters}};
  if (level.automatic) {
    summary["requested_clusters"] = "auto";
    const bool by_noise = level.noise && level.noise->level_by_noise;
    summary["rule"] = by_noise ? "noise" : to_string(level.automatic->rule);
    nlohmann::json candidates = nlohmann::json::array();
    for (const LevelCandidate& c : level.automatic->candidates)
      candidates.push_back({{"clusters", c.clusters},
                            {"rms", c.rms},
                            {"score", c.score},
                            {"merge_score", c.merge_score}});
    summary["candidates"] = std::move(candidates);
    if (level.noise) {
      summary["noise_estimate"] = level.noise->estimate;
      summary["noise_tolerance"] = level.noise->tolerance;
      if (level.automatic->rule == AutoLevelRule::Jump)
        summary["jump_worst_rms"] = level.noise->jump_worst_rms;
    }
  } else if (options.level.clusters) {
    summary["requested_clusters"] = *parse_cluster_count(*options.level.clusters);
  } else {
    summary["tolerance"] = options.level.tolerance.value_or(kDefaultTolerance);
  }
  return summary;
}

}  // namespace primseg::cli
