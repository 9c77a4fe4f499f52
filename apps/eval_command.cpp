// `primseg eval`: segmentation quality over the generated shapes with known ground truth.
#include <algorithm>
#include <cstdio>
#include <memory>

#include "../src/file_io.hpp"
#include "command.hpp"
#include "primseg/auto_level.hpp"
#include "primseg/error.hpp"
#include "primseg/evaluation.hpp"
#include "primseg/refine.hpp"
#include "primseg/shape_generator.hpp"

namespace primseg::cli {
namespace {

struct Variant {
  std::string name;
  Tessellation tessellation;
  double noise;
};

// The data set's three variants: CAD-style tessellation, uniform remeshing, and uniform with
// Gaussian noise of 0.2% of the diagonal along the normals.
const Variant kVariants[] = {{"cad", Tessellation::Cad, 0.0},
                             {"uniform", Tessellation::Uniform, 0.0},
                             {"noisy", Tessellation::Uniform, 0.002}};

// Sums of one group of cases (a variant, or everything).
struct Totals {
  int cases = 0, auto_exact = 0, auto_within_one = 0;
  double iou = 0, type_accuracy = 0, rand_index = 0, seconds = 0;
  std::array<double, kPrimitiveTypeCount> area{}, correct{};

  void add(const SegmentationScore& s, std::uint32_t truth, std::uint32_t chosen, double time) {
    ++cases;
    auto_exact += chosen == truth;
    auto_within_one += chosen + 1 >= truth && chosen <= truth + 1;
    iou += s.mean_iou;
    type_accuracy += s.type_accuracy;
    rand_index += s.rand_index;
    seconds += time;
    for (int t = 0; t < kPrimitiveTypeCount; ++t) {
      area[t] += s.area_by_type[t];
      correct[t] += s.correct_area_by_type[t];
    }
  }
  nlohmann::json json() const {
    nlohmann::json per_type = nlohmann::json::object();
    for (int t = 0; t < kPrimitiveTypeCount; ++t)
      if (area[t] > 0)
        per_type[std::string(to_string(static_cast<PrimitiveType>(t)))] = correct[t] / area[t];
    return {{"cases", cases},
            {"mean_iou", iou / cases},
            {"type_accuracy", type_accuracy / cases},
            {"rand_index", rand_index / cases},
            {"type_accuracy_by_type", per_type},
            {"auto_level_exact", double(auto_exact) / cases},
            {"auto_level_within_one", double(auto_within_one) / cases},
            {"seconds", seconds}};
  }
  void print(const std::string& name) const {
    std::printf("%-8s %5d  %8.4f  %8.4f  %8.4f  %7.3f  %7.3f  %8.3f\n", name.c_str(), cases,
                iou / cases, type_accuracy / cases, rand_index / cases, double(auto_exact) / cases,
                double(auto_within_one) / cases, seconds);
  }
};

struct EvalCommandOptions {
  std::string variants = "cad,uniform,noisy", shapes, primitives = "plane,cylinder,sphere";
  std::uint32_t seeds = 3, refine = 0;
  unsigned threads = 0;
  double merge_batch_tolerance = 0;
  std::optional<std::string> json;
  bool quiet = false;
};

// The variants of a --variants list, in its order.
std::vector<const Variant*> chosen_variants(const std::string& list) {
  std::vector<const Variant*> variants;
  for (const std::string& name : split_comma_list(list)) {
    const auto it = std::find_if(std::begin(kVariants), std::end(kVariants),
                                 [&](const Variant& v) { return v.name == name; });
    if (it == std::end(kVariants))
      throw InvalidInputError("--variants: unknown variant '" + name +
                              "' (available: cad, uniform, noisy)");
    variants.push_back(it);
  }
  return variants;
}

// One shape of one variant and seed, segmented at its true number of regions and scored.
struct EvalCase {
  SegmentationScore score;
  std::uint32_t faces = 0, truth = 0, auto_clusters = 0;
  double seconds = 0;  // the hierarchy, the cut and the cluster reports (or the refinement)
};

EvalCase evaluate(const std::string& shape_name, const Variant& variant, std::uint32_t seed,
                  const HierarchyOptions& options, std::uint32_t refine) {
  ShapeOptions shape_options;
  shape_options.tessellation = variant.tessellation;
  shape_options.noise = variant.noise;
  shape_options.random_motion = true;
  shape_options.seed = seed;
  const GroundTruthShape shape = make_shape(shape_name, shape_options);
  const auto start = Clock::now();
  const Hierarchy hierarchy = build_hierarchy(shape.mesh, options);
  EvalCase result;
  result.faces = shape.mesh.face_count();
  result.truth = static_cast<std::uint32_t>(shape.regions.size());
  Segmentation segmentation = cut_by_count(hierarchy, result.truth);
  std::vector<ClusterReport> reports;
  if (refine > 0) {
    BoundaryRefinementOptions refine_options;
    refine_options.max_passes = refine;
    RefinedLevel refined = refine_boundaries(hierarchy, segmentation, refine_options);
    segmentation = std::move(refined.segmentation);
    reports = std::move(refined.reports);
  } else {
    reports = describe_clusters(hierarchy, segmentation);
  }
  result.seconds = seconds_since(start);
  result.auto_clusters = choose_level(hierarchy).clusters;
  std::vector<PrimitiveType> types, truth_types;
  for (const ClusterReport& r : reports) types.push_back(r.primitive.type);
  for (const Primitive& p : shape.regions) truth_types.push_back(p.type);
  result.score = score_segmentation(segmentation.labels, shape.region_of_face,
                                    face_areas(shape.mesh), types, truth_types);
  return result;
}

// Runs `primseg eval` with its parsed options.
void run_eval(const EvalCommandOptions& o) {
  HierarchyOptions options;
  options.primitives = parse_primitives(o.primitives);
  options.threads = o.threads;
  options.merge_batch_tolerance = o.merge_batch_tolerance;
  validate(options);
  const std::vector<const Variant*> variants = chosen_variants(o.variants);
  const std::vector<std::string> shapes =
      o.shapes.empty() ? shape_names() : split_comma_list(o.shapes);
  for (const std::string& name : shapes) make_shape(name);  // unknown names fail first

  nlohmann::json cases = nlohmann::json::array();
  Totals all;
  std::vector<Totals> by_variant(variants.size());
  if (!o.quiet)
    std::printf("%-8s %-26s %4s  %6s  %5s  %6s  %6s  %6s  %4s  %8s\n", "variant", "shape", "seed",
                "faces", "truth", "iou", "types", "rand", "auto", "seconds");
  for (std::size_t v = 0; v < variants.size(); ++v)
    for (const std::string& name : shapes)
      for (std::uint32_t seed = 1; seed <= o.seeds; ++seed) {
        const EvalCase c = evaluate(name, *variants[v], seed, options, o.refine);
        all.add(c.score, c.truth, c.auto_clusters, c.seconds);
        by_variant[v].add(c.score, c.truth, c.auto_clusters, c.seconds);
        if (!o.quiet)
          std::printf("%-8s %-26s %4u  %6u  %5u  %6.4f  %6.4f  %6.4f  %4u  %8.3f\n",
                      variants[v]->name.c_str(), name.c_str(), seed, c.faces, c.truth,
                      c.score.mean_iou, c.score.type_accuracy, c.score.rand_index, c.auto_clusters,
                      c.seconds);
        cases.push_back({{"variant", variants[v]->name},
                         {"shape", name},
                         {"seed", seed},
                         {"faces", c.faces},
                         {"regions", c.truth},
                         {"mean_iou", c.score.mean_iou},
                         {"min_iou", c.score.min_iou},
                         {"type_accuracy", c.score.type_accuracy},
                         {"rand_index", c.score.rand_index},
                         {"auto_clusters", c.auto_clusters},
                         {"seconds", c.seconds}});
      }
  std::printf("\n%-8s %5s  %8s  %8s  %8s  %7s  %7s  %8s\n", "variant", "cases", "mean_iou", "types",
              "rand", "auto=", "auto±1", "seconds");
  nlohmann::json totals;
  for (std::size_t v = 0; v < variants.size(); ++v) {
    by_variant[v].print(variants[v]->name);
    totals[variants[v]->name] = by_variant[v].json();
  }
  all.print("all");
  totals["all"] = all.json();
  for (int t = 0; t < kPrimitiveTypeCount; ++t)
    if (all.area[t] > 0)
      std::printf("type accuracy, %s regions: %.4f\n",
                  std::string(to_string(static_cast<PrimitiveType>(t))).c_str(),
                  all.correct[t] / all.area[t]);
  if (o.json)
    detail::write_file_atomically(
        *o.json, nlohmann::json{{"cases", cases}, {"totals", totals}}.dump(2) + "\n");
}

}  // namespace

Command add_eval_command(CLI::App& app) {
  auto o = std::make_shared<EvalCommandOptions>();
  auto* eval = app.add_subcommand(
      "eval",
      "Score the segmenter on the generated shapes with ground truth: mean IoU, type accuracy "
      "and Rand index at the true number of regions, and the automatic level's choice");
  eval->add_option("--variants", o->variants, "Variants, comma-separated: cad, uniform, noisy")
      ->capture_default_str();
  eval->add_option("--shapes", o->shapes, "Shapes, comma-separated (default: the whole catalogue)");
  eval->add_option("--seeds", o->seeds, "Random rigid motions (and noise draws) per shape")
      ->check(CLI::Range(1u, 1000u))
      ->capture_default_str();
  eval->add_option("--primitives", o->primitives, "Primitive types, comma-separated")
      ->capture_default_str();
  eval->add_option("--threads", o->threads, "Threads of the hierarchy (0: all cores)")
      ->capture_default_str();
  add_merge_batch_option(*eval, o->merge_batch_tolerance);
  eval->add_option("--refine", o->refine, "Boundary refinement passes after the cut (0: none)")
      ->check(CLI::Range(0u, 1000u))
      ->capture_default_str();
  eval->add_option("--json", o->json, "Write every case and the totals as JSON");
  eval->add_flag("--quiet,-q", o->quiet, "Print the totals only");

  return {eval, [o] { run_eval(*o); }};
}

}  // namespace primseg::cli
