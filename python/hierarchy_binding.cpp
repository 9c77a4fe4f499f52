// Hierarchy, the whole merge tree: segment() builds it, read_tree() reads it, and its methods give
// its levels (cut, clusters, borders, relations), error curve, linkage matrix and merges.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "../src/length_text.hpp"
#include "../src/parallel.hpp"
#include "../src/tree_nodes.hpp"
#include "binding_support.hpp"
#include "bindings.hpp"
#include "doxygen_docstrings.hpp"
#include "primseg/auto_level.hpp"
#include "primseg/borders.hpp"
#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/primitive.hpp"
#include "primseg/refine.hpp"
#include "primseg/relations.hpp"
#include "primseg/tree_io.hpp"

namespace primseg::python {
namespace {

PyHierarchy segment_mesh(std::shared_ptr<const Mesh> mesh, const HierarchyOptions& options,
                         const py::object& progress) {
  const std::function<void(double)> report = python_progress(progress);
  return without_gil([&] {
    HierarchyBuilder builder(std::move(mesh), options);
    return PyHierarchy{std::make_shared<const Hierarchy>(builder.finish(report))};
  });
}

// The CLI's limit on --refine.
constexpr std::int64_t kMaxRefinePasses = 1000;
const char* kRefineArgument =
    R"(refine: up to this many passes of boundary refinement after the cut (the CLI's --refine N;
  0: none): border faces move to the adjacent cluster whose primitive fits them at least twice
  better, and the primitives are refitted. Raises InvalidInputError (a ValueError) outside
  0..1000.)";

const char* kRegularizeArgument =
    R"(regularize: make the fits' relations exact (the CLI's --regularize): plane normals and
  cylinder axes that agree within their uncertainty share one direction, cylinders one axis line
  (with the spheres centred on it), spheres of one centre share it, directions at right angles
  within it are made orthogonal, fragments of one face share one plane, cylinders and spheres of
  one radius share it, and fillets become tangent to the faces and cylinders they border;
  Hierarchy.relations() lists them.)";

const char* kRelationArguments =
    R"(relation_significance, max_relation_angle, max_radius_difference: the CLI's options of the
  same names (RelationOptions significance, max_angle_degrees, max_radius_difference): fits agree
  within relation_significance standard deviations (> 0), never beyond max_relation_angle degrees
  (in (0, 90)) or radii more than max_radius_difference apart (in (0, 1); a sphere's centre is
  put on an axis no farther than that fraction of its radius from it, and a cylinder made tangent
  to a plane or a parallel cylinder no farther than that fraction of its radius from tangent,
  nor its radius moved by more by the tangent refit).
  relation_angle_tolerance (degrees, at least 0 and below max_relation_angle) and
  relation_length_tolerance (input units, >= 0, or a string "L%": L percent of the bounding-box
  diagonal, as the CLI's --relation-length-tolerance L%; RelationOptions angle_tolerance_degrees,
  length_tolerance): directions, and axis lines, offsets, centres, radii and tangency gaps, that
  agree within them are related whatever their uncertainty (for CAD parts, whose tessellation errs
  by more than the fits' statistics allow); 0, the default, leaves the significance alone. Raise
  InvalidInputError (a ValueError) outside these ranges.)";

// relation_length_tolerance as Python gives it: a length (input units), or "L%", L percent of the
// bounding-box diagonal.
using LengthArgument = std::variant<double, std::string>;

// The length of `argument` on `mesh`: a percentage by the CLI's parser (detail::parse_length, the
// same double); InvalidInputError, naming the keyword, for a string that is not one.
double length_argument(const LengthArgument& argument, const Mesh& mesh) {
  if (const double* length = std::get_if<double>(&argument)) return *length;
  const std::string& text = std::get<std::string>(argument);
  if (!detail::is_percentage(text))
    throw InvalidInputError("relation_length_tolerance is '" + text +
                            "', must be a non-negative length or a percentage of the "
                            "bounding-box diagonal such as '0.01%'");
  return detail::parse_length(text, bounding_box_diagonal(mesh), "relation_length_tolerance");
}

// The RelationOptions of relation_significance, max_relation_angle, relation_angle_tolerance,
// relation_length_tolerance and max_radius_difference for a level of `mesh`; InvalidInputError,
// naming the keyword, outside their ranges.
RelationOptions relation_arguments(const Mesh& mesh, double significance, double max_angle,
                                   double angle_tolerance, const LengthArgument& length,
                                   double max_difference) {
  auto refuse = [](const char* keyword, double value, const char* range) {
    throw InvalidInputError(std::string(keyword) + " is " + std::to_string(value) + ", must be " +
                            range);
  };
  const double length_tolerance = length_argument(length, mesh);
  if (!(significance > 0 && std::isfinite(significance)))
    refuse("relation_significance", significance, "a positive number");
  if (!(max_angle > 0 && max_angle < 90)) refuse("max_relation_angle", max_angle, "in (0, 90)");
  if (!(angle_tolerance >= 0 && angle_tolerance < max_angle))
    refuse("relation_angle_tolerance", angle_tolerance, "at least 0 and below max_relation_angle");
  if (!(length_tolerance >= 0 && std::isfinite(length_tolerance)))
    refuse("relation_length_tolerance", length_tolerance, "a finite number at least 0");
  if (!(max_difference > 0 && max_difference < 1))
    refuse("max_radius_difference", max_difference, "in (0, 1)");
  RelationOptions options;
  options.significance = significance;
  options.max_angle_degrees = max_angle;
  options.angle_tolerance_degrees = angle_tolerance;
  options.length_tolerance = length_tolerance;
  options.max_radius_difference = max_difference;
  return options;
}

// The level, refined by up to `refine` boundary passes (0: as cut), with its cluster reports when
// `reports` is given, and their relations made exact when `relations` is given too: what the
// CLI's --refine N and --regularize write.
Segmentation refined_level(const Hierarchy& hierarchy, const LevelArguments& level,
                           std::int64_t refine, std::vector<ClusterReport>* reports,
                           std::vector<ClusterRelation>* relations = nullptr,
                           const RelationOptions& relation_options = {}) {
  if (refine < 0 || refine > kMaxRefinePasses)
    throw InvalidInputError("refine must be a number of passes in [0, " +
                            std::to_string(kMaxRefinePasses) + "], not " + std::to_string(refine));
  Segmentation segmentation = cut_level(hierarchy, level);
  if (refine > 0) {
    BoundaryRefinementOptions options;
    options.max_passes = static_cast<std::uint32_t>(refine);
    RefinedLevel refined = refine_boundaries(hierarchy, segmentation, options);
    segmentation = std::move(refined.segmentation);
    if (reports) *reports = std::move(refined.reports);
  } else if (reports) {
    *reports = describe_clusters(hierarchy, segmentation);
  }
  if (reports && relations)
    *relations = regularize_clusters(hierarchy, segmentation, *reports, relation_options);
  return segmentation;
}

// The levels of `counts` clusters (each 1..F, in any order, repeats allowed), each with its
// clusters' reports and relations as refined_level() gives them with refine 0 and `relations`,
// bit for bit: one LevelRegularizer over the clusters of these levels alone (as the CLI's view
// --regularize), then the levels on `threads` threads (0: all cores), each computed once.
// Shape (counts.size()), in the order of `counts`.
std::vector<RegularizedLevel> regularized_levels(const Hierarchy& hierarchy,
                                                 const std::vector<std::uint32_t>& counts,
                                                 const RelationOptions& options, unsigned threads) {
  if (counts.empty()) return {};
  // The distinct levels, most clusters first: the costliest start first on the threads.
  std::vector<std::uint32_t> distinct = counts;
  std::sort(distinct.begin(), distinct.end(), std::greater<>());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  std::vector<std::uint32_t> nodes;
  for (const std::uint32_t clusters : distinct) {
    const std::vector<std::uint32_t> level = detail::level_nodes(hierarchy, clusters);
    nodes.insert(nodes.end(), level.begin(), level.end());
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  DescribeOptions describe;
  describe.threads = threads;
  const std::vector<ClusterReport> reports = describe_nodes(hierarchy, nodes, describe);
  const LevelRegularizer regularizer(hierarchy, nodes, reports, options, threads);
  std::vector<RegularizedLevel> levels(distinct.size());
  detail::parallel_for_threads(
      distinct.size(), detail::thread_count(threads),
      [&](std::size_t i, unsigned) { levels[i] = regularizer.level(distinct[i]); });
  std::vector<RegularizedLevel> ordered;
  ordered.reserve(counts.size());
  for (const std::uint32_t clusters : counts) {
    const auto at = std::lower_bound(distinct.begin(), distinct.end(), clusters, std::greater<>());
    ordered.push_back(levels[static_cast<std::size_t>(at - distinct.begin())]);
  }
  return ordered;
}

const char* kLevelArguments =
    R"(Exactly one level, or none for the CLI's default (relative_tolerance=0.001, i.e.
`--tolerance 0.1%`):
  k: number of clusters, 1..F (below the number of connected components C you get C), or
    "auto": the most significant level of the error curve (the CLI's --clusters auto);
  tolerance: the coarsest level whose clusters each have an RMS distance estimate of at
    most `tolerance` to their primitive, input units;
  relative_tolerance: the same as a fraction of the bounding-box diagonal (0.001 = 0.1%).
Raises InvalidInputError (a ValueError) for k outside 1..F, a string other than "auto", or a
negative or NaN tolerance.)";

void bind_segment(py::module_& m) {
  const char* segment_doc =
      R"(segment(mesh, *, primitives=("plane", "cylinder", "sphere"), weights="area", threads=0, exact_costs=False, eager=False, merge_batch_tolerance=0.0, regions=1, progress=None) -> Hierarchy
segment(V, F, *, ...) -> Hierarchy

Builds the whole hierarchy, with the GIL released. About every percent of the merges it takes the
GIL back for a moment: Ctrl-C (KeyboardInterrupt) stops the build there, and progress, if given,
is called with the fraction done (0 to 1; a progress bar); an exception it raises stops the
build and propagates. The input is a Mesh (read_mesh: labels are per input polygon, like the
CLI's) or arrays V (n, 3) float32/float64 and F (m, 3) int32/int64/uint32/uint64, C- or
Fortran-ordered, read in place without a converted copy (labels are per row of F).
primitives: names or one name ("plane", "cylinder", "sphere"); weights: "area" or "uniform";
threads: 0 for all cores (the tree does not depend on it); exact_costs: slow reference mode;
eager: evaluate every candidate at once (reference mode, the same tree);
merge_batch_tolerance: above 0, an approximate merge order, faster (0.1 is a good start);
regions: above 1, an approximate merge order, faster on several cores (2 on two cores).
Raises InvalidInputError (a ValueError) for bad arrays (shape, dtype, NaN or infinite
coordinates, index out of range, no faces) or bad options.)";
  m.def(
      "segment",
      [](const py::object& first, const py::object& faces, const py::object& primitives,
         const std::string& weights, unsigned threads, bool exact_costs, bool eager,
         double merge_batch_tolerance, unsigned regions, const py::object& progress) {
        const HierarchyOptions options = hierarchy_options(
            primitives, weights, threads, exact_costs, eager, merge_batch_tolerance, regions);
        return segment_mesh(mesh_argument("segment", first, faces), options, progress);
      },
      py::arg("mesh_or_V"), py::arg("F") = py::none(), py::kw_only(),
      py::arg("primitives") = py::make_tuple("plane", "cylinder", "sphere"),
      py::arg("weights") = "area", py::arg("threads") = 0u, py::arg("exact_costs") = false,
      py::arg("eager") = false, py::arg("merge_batch_tolerance") = 0.0, py::arg("regions") = 1u,
      py::arg("progress") = py::none(),
      join_docs(
          {segment_doc, cpp_doc("build_hierarchy", doc::hierarchy__build_hierarchy_2),
           cpp_doc("HierarchyOptions::primitives", doc::hierarchy__HierarchyOptions__primitives),
           cpp_doc("HierarchyOptions::weights", doc::hierarchy__HierarchyOptions__weights),
           cpp_doc("HierarchyOptions::threads", doc::hierarchy__HierarchyOptions__threads),
           cpp_doc("HierarchyOptions::evaluation", doc::hierarchy__HierarchyOptions__evaluation),
           cpp_doc("HierarchyOptions::exact_costs", doc::hierarchy__HierarchyOptions__exact_costs),
           cpp_doc("HierarchyOptions::merge_batch_tolerance",
                   doc::hierarchy__HierarchyOptions__merge_batch_tolerance),
           cpp_doc("HierarchyOptions::regions", doc::hierarchy__HierarchyOptions__regions)})
          .c_str());
}

}  // namespace

py::class_<PyHierarchy> declare_hierarchy_class(py::module_& m) {
  return py::class_<PyHierarchy>(
      m, "Hierarchy",
      join_docs({"The whole merge tree of a mesh (from segment or read_tree). Read-only; pickles "
                 "as its tree file's bytes (Hierarchy.save).",
                 cpp_doc("Hierarchy", doc::hierarchy__Hierarchy)})
          .c_str());
}

void bind_hierarchy(py::module_& m, py::class_<PyHierarchy>& hierarchy_class) {
  bind_segment(m);
  m.def(
      "read_tree",
      [](const std::filesystem::path& path) {
        py::gil_scoped_release release;
        return PyHierarchy{std::make_shared<const Hierarchy>(read_tree(path))};
      },
      py::arg("path"),
      join_docs({"read_tree(path) -> Hierarchy: a tree file written by Hierarchy.save or the "
                 "CLI's --tree.",
                 cpp_doc("read_tree", doc::tree_io__read_tree)})
          .c_str());

  hierarchy_class
      .def(
          "cut",
          [](const PyHierarchy& self, ClusterCount k, std::optional<double> tolerance,
             std::optional<double> relative_tolerance, std::int64_t refine) {
            const LevelArguments level{std::move(k), tolerance, relative_tolerance};
            Segmentation segmentation;
            {
              py::gil_scoped_release release;
              segmentation = refined_level(*self.hierarchy, level, refine, nullptr);
            }
            const py::ssize_t faces = static_cast<py::ssize_t>(segmentation.labels.size());
            return adopt<std::int32_t>(std::move(segmentation.labels), {faces});
          },
          py::arg("k") = py::none(), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("relative_tolerance") = py::none(), py::arg("refine") = 0,
          join_docs(
              {R"(cut(k=None, *, tolerance=None, relative_tolerance=None, refine=0) -> numpy.ndarray

The cluster of each input face, int32 (F,), values 0..K-1 numbered by decreasing area: the same
labels as the CLI's --labels.)",
               kLevelArguments, kRefineArgument, cpp_doc("cut_by_count", doc::cut__cut_by_count),
               cpp_doc("cut_by_tolerance", doc::cut__cut_by_tolerance),
               cpp_doc("refine_boundaries", doc::refine__refine_boundaries)})
              .c_str())
      .def(
          "clusters",
          [](const PyHierarchy& self, ClusterCount k, std::optional<double> tolerance,
             std::optional<double> relative_tolerance, std::int64_t refine, bool regularize,
             double significance, double max_angle, double angle_tolerance,
             const LengthArgument& length_tolerance, double max_difference) {
            const LevelArguments level{std::move(k), tolerance, relative_tolerance};
            std::vector<ClusterReport> reports;
            {
              py::gil_scoped_release release;
              std::vector<ClusterRelation> relations;
              refined_level(*self.hierarchy, level, refine, &reports,
                            regularize ? &relations : nullptr,
                            relation_arguments(self.hierarchy->mesh(), significance, max_angle,
                                               angle_tolerance, length_tolerance, max_difference));
            }
            py::list clusters;
            for (const ClusterReport& report : reports) clusters.append(cluster_dict(report));
            return clusters;
          },
          py::arg("k") = py::none(), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("relative_tolerance") = py::none(), py::arg("refine") = 0,
          py::arg("regularize") = false,
          py::arg("relation_significance") = RelationOptions{}.significance,
          py::arg("max_relation_angle") = RelationOptions{}.max_angle_degrees,
          py::arg("relation_angle_tolerance") = RelationOptions{}.angle_tolerance_degrees,
          py::arg("relation_length_tolerance") = RelationOptions{}.length_tolerance,
          py::arg("max_radius_difference") = RelationOptions{}.max_radius_difference,
          join_docs(
              {R"(clusters(k=None, *, tolerance=None, relative_tolerance=None, refine=0, regularize=False, relation_significance=3.0, max_relation_angle=20.0, relation_angle_tolerance=0.0, relation_length_tolerance=0.0, max_radius_difference=0.05) -> list of dict

One dict per cluster, in label order, with the keys and values of the CLI's --json "clusters":
id, type ("plane", "cylinder", "sphere"), faces (count), area, rms, max, and params (input
units: plane {normal, point}, sphere {center, radius}, cylinder {axis, point, radius}; vectors
as lists). json.dumps() takes it as it is.)",
               kLevelArguments, kRefineArgument, kRegularizeArgument, kRelationArguments,
               cpp_doc("ClusterReport", doc::cut__ClusterReport),
               cpp_doc("ClusterReport::rms", doc::cut__ClusterReport__rms),
               cpp_doc("ClusterReport::max", doc::cut__ClusterReport__max),
               cpp_doc("named_parameters", doc::primitive__named_parameters)})
              .c_str())
      .def(
          "borders",
          [](const PyHierarchy& self, ClusterCount k, std::optional<double> tolerance,
             std::optional<double> relative_tolerance, std::int64_t refine, bool regularize,
             double significance, double max_angle, double angle_tolerance,
             const LengthArgument& length_tolerance, double max_difference) {
            const LevelArguments level{std::move(k), tolerance, relative_tolerance};
            std::vector<ClusterBorder> borders;
            {
              py::gil_scoped_release release;
              std::vector<ClusterReport> reports;
              std::vector<ClusterRelation> relations;
              const Segmentation segmentation = refined_level(
                  *self.hierarchy, level, refine, &reports, regularize ? &relations : nullptr,
                  relation_arguments(self.hierarchy->mesh(), significance, max_angle,
                                     angle_tolerance, length_tolerance, max_difference));
              borders = cluster_borders(self.hierarchy->mesh(), segmentation.labels,
                                        cluster_primitives(reports));
            }
            py::list list;
            for (const ClusterBorder& border : borders) list.append(border_dict(border));
            return list;
          },
          py::arg("k") = py::none(), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("relative_tolerance") = py::none(), py::arg("refine") = 0,
          py::arg("regularize") = false,
          py::arg("relation_significance") = RelationOptions{}.significance,
          py::arg("max_relation_angle") = RelationOptions{}.max_angle_degrees,
          py::arg("relation_angle_tolerance") = RelationOptions{}.angle_tolerance_degrees,
          py::arg("relation_length_tolerance") = RelationOptions{}.length_tolerance,
          py::arg("max_radius_difference") = RelationOptions{}.max_radius_difference,
          join_docs(
              {R"(borders(k=None, *, tolerance=None, relative_tolerance=None, refine=0, regularize=False, relation_significance=3.0, max_relation_angle=20.0, relation_angle_tolerance=0.0, relation_length_tolerance=0.0, max_radius_difference=0.05) -> list of dict

Where the clusters of the level meet, as the CLI's --json "borders": one dict per border with
clusters (a, b), b None along the mesh's open boundary; edges (count); length (input units);
angle (degrees between the two fitted surfaces across it: 0 tangent, 90 a box's edge; None on
the open boundary); and curves, a list of dicts {closed, vertices} with the vertex indices in
order along each curve. json.dumps() takes it as it is.)",
               kLevelArguments, kRefineArgument, kRegularizeArgument, kRelationArguments,
               cpp_doc("cluster_borders", doc::borders__cluster_borders),
               cpp_doc("ClusterBorder::angle", doc::borders__ClusterBorder__angle),
               cpp_doc("ClusterBorder::curves", doc::borders__ClusterBorder__curves)})
              .c_str())
      .def(
          "relations",
          [](const PyHierarchy& self, ClusterCount k, std::optional<double> tolerance,
             std::optional<double> relative_tolerance, std::int64_t refine, double significance,
             double max_angle, double angle_tolerance, const LengthArgument& length_tolerance,
             double max_difference) {
            const LevelArguments level{std::move(k), tolerance, relative_tolerance};
            std::vector<ClusterRelation> relations;
            {
              py::gil_scoped_release release;
              std::vector<ClusterReport> reports;
              refined_level(*self.hierarchy, level, refine, &reports, &relations,
                            relation_arguments(self.hierarchy->mesh(), significance, max_angle,
                                               angle_tolerance, length_tolerance, max_difference));
            }
            return relations_list(relations);
          },
          py::arg("k") = py::none(), py::kw_only(), py::arg("tolerance") = py::none(),
          py::arg("relative_tolerance") = py::none(), py::arg("refine") = 0,
          py::arg("relation_significance") = RelationOptions{}.significance,
          py::arg("max_relation_angle") = RelationOptions{}.max_angle_degrees,
          py::arg("relation_angle_tolerance") = RelationOptions{}.angle_tolerance_degrees,
          py::arg("relation_length_tolerance") = RelationOptions{}.length_tolerance,
          py::arg("max_radius_difference") = RelationOptions{}.max_radius_difference,
          join_docs(
              {R"(relations(k=None, *, tolerance=None, relative_tolerance=None, refine=0, relation_significance=3.0, max_relation_angle=20.0, relation_angle_tolerance=0.0, relation_length_tolerance=0.0, max_radius_difference=0.05) -> list of dict

The design intent among the level's fits, as the CLI's --regularize writes it in the JSON's
"relations": one dict per relation with kind ("parallel": plane normals and cylinder axes of one
direction; "coaxial": cylinders of one axis line and spheres centred on it, or three spheres or
more centred on one line with no cylinder; "orthogonal": two directions at right angles;
"equal_radius": cylinders and spheres of one radius; "coplanar": planes of one plane, the
fragments of one face; "tangent": a cylinder and a plane it borders, the cylinder tangent to it,
as a fillet and the face it rounds, or two parallel cylinders that border each other, as a fillet
and the boss it rounds; "concentric": spheres of one centre, as a ball and its socket) and clusters (their labels, increasing; for
"orthogonal", those of one direction, and orthogonal_to those of the other), and deviation: how
far the clusters' own fits were from the relation (degrees for "parallel" and "orthogonal", input
units otherwise), what a tolerance must reach for it to hold whatever the statistics.
clusters(..., regularize=True) gives the primitives with these relations made exact.)",
               kLevelArguments, kRefineArgument, kRelationArguments,
               cpp_doc("regularize_clusters", doc::relations__regularize_clusters),
               cpp_doc("relations.hpp", doc::relations__file)})
              .c_str())
      .def(
          "relations_of_levels",
          [](const PyHierarchy& self, const std::vector<std::int64_t>& ks, double significance,
             double max_angle, double angle_tolerance, const LengthArgument& length_tolerance,
             double max_difference, unsigned threads) {
            const RelationOptions options =
                relation_arguments(self.hierarchy->mesh(), significance, max_angle, angle_tolerance,
                                   length_tolerance, max_difference);
            std::vector<std::uint32_t> counts;
            counts.reserve(ks.size());
            for (std::size_t i = 0; i < ks.size(); ++i) {
              try {
                validate_level({ks[i], std::nullopt, std::nullopt}, self.hierarchy->face_count());
              } catch (const InvalidInputError& error) {
                throw InvalidInputError("ks[" + std::to_string(i) + "]: " + error.what());
              }
              counts.push_back(static_cast<std::uint32_t>(ks[i]));
            }
            std::vector<RegularizedLevel> levels;
            {
              py::gil_scoped_release release;
              levels = regularized_levels(*self.hierarchy, counts, options, threads);
            }
            py::list list;
            for (std::size_t i = 0; i < levels.size(); ++i) {
              py::list clusters;
              for (const ClusterReport& report : levels[i].reports)
                clusters.append(cluster_dict(report));
              py::dict level;
              level["k"] = ks[i];
              level["clusters"] = clusters;
              level["relations"] = relations_list(levels[i].relations);
              list.append(level);
            }
            return list;
          },
          py::arg("ks"), py::kw_only(),
          py::arg("relation_significance") = RelationOptions{}.significance,
          py::arg("max_relation_angle") = RelationOptions{}.max_angle_degrees,
          py::arg("relation_angle_tolerance") = RelationOptions{}.angle_tolerance_degrees,
          py::arg("relation_length_tolerance") = RelationOptions{}.length_tolerance,
          py::arg("max_radius_difference") = RelationOptions{}.max_radius_difference,
          py::arg("threads") = 0u,
          join_docs(
              {R"(relations_of_levels(ks, *, relation_significance=3.0, max_relation_angle=20.0, relation_angle_tolerance=0.0, relation_length_tolerance=0.0, max_radius_difference=0.05, threads=0) -> list of dict

The relations and the regularized fits of many levels at once: one dict per entry of ks (numbers
of clusters, in their order; repeats allowed) with k (the entry), clusters (the list
clusters(k, regularize=True) gives) and relations (the list relations(k) gives), equal to those
calls' results bit for bit. Each of those calls gathers the vertices of every cluster from all F
faces; this gathers those of the clusters of the levels asked for once, so that a level then
costs its relations alone (as the CLI's view --regularize browses them level by level): for
levels 1..100, a fraction of the time of the calls one by one. ks = [] gives []. Raises
InvalidInputError (a ValueError) naming the entry, "ks[i]: k must be between 1 and the number
of faces (F), not ...", and TypeError for an entry that is not an integer.)",
               kRelationArguments,
               R"(threads: 0 for all cores (the results do not depend on it); the levels, the fits
  of their clusters and the gathering of their vertices run on them.)",
               cpp_doc("LevelRegularizer", doc::relations__LevelRegularizer),
               cpp_doc("LevelRegularizer::level", doc::relations__LevelRegularizer__level)})
              .c_str())
      .def(
          "auto_level",
          [](const PyHierarchy& self) {
            AutoLevel level;
            {
              py::gil_scoped_release release;
              level = choose_level(*self.hierarchy);
            }
            py::list candidates;
            for (const LevelCandidate& c : level.candidates) {
              py::dict candidate;
              candidate["clusters"] = c.clusters;
              candidate["rms"] = c.rms;
              candidate["score"] = c.score;
              candidate["merge_score"] = c.merge_score;
              candidates.append(candidate);
            }
            py::dict d;
            d["clusters"] = level.clusters;
            d["rule"] = std::string(to_string(level.rule));
            d["candidates"] = candidates;
            return d;
          },
          join_docs({R"(auto_level() -> dict

The level cut("auto") takes and why, as the CLI's --json "level" reports it: clusters (K), rule
("jump", "knee" or "components") and candidates (best score first: dicts of clusters, rms in
input units, score and merge_score).)",
                     cpp_doc("choose_level", doc::auto_level__choose_level),
                     cpp_doc("AutoLevel::clusters", doc::auto_level__AutoLevel__clusters),
                     cpp_doc("LevelCandidate::score", doc::auto_level__LevelCandidate__score),
                     cpp_doc("LevelCandidate::merge_score",
                             doc::auto_level__LevelCandidate__merge_score)})
              .c_str())
      .def(
          "error_curve",
          [](const PyHierarchy& self) {
            std::vector<ErrorCurvePoint> points;
            {
              py::gil_scoped_release release;
              points = error_curve(*self.hierarchy);
            }
            std::vector<std::array<double, 2>> rows(points.size());
            for (std::size_t i = 0; i < points.size(); ++i)
              rows[i] = {static_cast<double>(points[i].clusters), points[i].rms};
            const py::ssize_t count = static_cast<py::ssize_t>(rows.size());
            return adopt<double>(std::move(rows), {count, 2});
          },
          join_docs({R"(error_curve() -> numpy.ndarray

The RMS distance estimate of every level, float64 (F - C + 1, 2): rows (K, rms) for K from the
number of components C to F, in input units; the CLI's --curve CSV. To plot and choose a level
by eye: plt.semilogy(*curve.T).)",
                     cpp_doc("error_curve", doc::auto_level__error_curve),
                     cpp_doc("ErrorCurvePoint::rms", doc::auto_level__ErrorCurvePoint__rms)})
              .c_str())
      .def(
          "linkage",
          [](const PyHierarchy& self) {
            std::vector<std::array<double, 4>> rows = scipy_linkage(*self.hierarchy);
            const py::ssize_t count = static_cast<py::ssize_t>(rows.size());
            return adopt<double>(std::move(rows), {count, 4});
          },
          join_docs({R"(linkage() -> numpy.ndarray

The whole tree as SciPy's (F - 1, 4) float64 linkage matrix (children ids, height, size), for
scipy.cluster.hierarchy: cut_tree(Z, n_clusters=k) and fcluster(Z, k, "maxclust") give the
same clusters as cut(k). The same matrix as the CLI's --linkage.)",
                     cpp_doc("scipy_linkage", doc::cut__scipy_linkage),
                     cpp_doc("Merge::cost", doc::hierarchy__Merge__cost)})
              .c_str())
      .def(
          "merges",
          [](const PyHierarchy& self) {
            const Hierarchy& tree = *self.hierarchy;
            const std::span<const Merge> merges = tree.merges();
            const std::size_t n = merges.size();
            const auto rows = static_cast<py::ssize_t>(n);
            std::vector<std::array<std::int32_t, 2>> children(n);
            std::vector<std::int32_t> face_count(n);
            std::vector<std::uint8_t> trailing(n);
            std::vector<std::int8_t> type(n);
            std::vector<Vec3> point(n), axis(n);
            std::vector<double> rms(n), radius(n), minor_radius(n), half_angle(n);
            for (std::size_t i = 0; i < n; ++i) {
              const Merge& merge = merges[i];
              children[i] = {static_cast<std::int32_t>(merge.first),
                             static_cast<std::int32_t>(merge.second)};
              face_count[i] = static_cast<std::int32_t>(merge.face_count);
              trailing[i] = merge.trailing ? 1 : 0;
              type[i] = merge.trailing ? -1 : static_cast<std::int8_t>(merge.primitive.type);
              rms[i] = merge.trailing
                           ? std::numeric_limits<double>::quiet_NaN()
                           : tree.rms_estimate(tree.face_count() + static_cast<std::uint32_t>(i));
              point[i] = merge.primitive.point;
              axis[i] = merge.primitive.axis;
              radius[i] = merge.primitive.radius;
              minor_radius[i] = merge.primitive.minor_radius;
              half_angle[i] = merge.primitive.half_angle;
            }
            // Type names by code, "" for the trailing merges (code -1, the last entry).
            py::list names;
            for (int t = 0; t < kPrimitiveTypeCount; ++t)
              names.append(std::string(to_string(static_cast<PrimitiveType>(t))));
            names.append("");
            const py::module_ numpy = py::module_::import("numpy");
            py::dict table;
            table["children"] = adopt<std::int32_t>(std::move(children), {rows, 2});
            table["face_count"] = adopt<std::int32_t>(std::move(face_count), {rows});
            table["trailing"] = adopt<bool>(std::move(trailing), {rows});  // bytes 0 and 1
            table["type"] = numpy.attr("array")(names).attr("__getitem__")(
                adopt<std::int8_t>(std::move(type), {rows}));
            table["rms"] = adopt<double>(std::move(rms), {rows});
            table["point"] = adopt<double>(std::move(point), {rows, 3});
            table["axis"] = adopt<double>(std::move(axis), {rows, 3});
            table["radius"] = adopt<double>(std::move(radius), {rows});
            table["minor_radius"] = adopt<double>(std::move(minor_radius), {rows});
            table["half_angle"] = adopt<double>(std::move(half_angle), {rows});
            return table;
          },
          join_docs({R"(merges() -> dict

Every merge of the tree, one row per node it makes (row i is node F + i; nodes 0..F-1 are the
faces), as numpy arrays of length F - 1: children (F - 1, 2) int32 (node ids, as linkage()),
face_count int32, trailing bool (merges joining connected components after all real ones: no
fit), and the primitive the greedy fitted to the node from its moments: type str ("plane",
"cylinder", "sphere", "cone", "torus"; "" when trailing), rms float64 (the node's RMS distance
estimate, input units; NaN when trailing), point and axis (F - 1, 3) float64, radius,
minor_radius and half_angle float64 (radians), in input units, zero where the type has none.
Hierarchy.clusters() refits a level's clusters geometrically and measures their exact errors;
these are the tree's own fits, for rules of one's own over all nodes.)",
                     cpp_doc("Merge", doc::hierarchy__Merge),
                     cpp_doc("Hierarchy::rms_estimate", doc::hierarchy__Hierarchy__rms_estimate)})
              .c_str())
      .def(
          "save",
          [](const PyHierarchy& self, const std::filesystem::path& path) {
            py::gil_scoped_release release;
            write_tree(path, *self.hierarchy);
          },
          py::arg("path"),
          join_docs({"save(path): the tree file (read_tree, or the CLI's `primseg cut`).",
                     cpp_doc("write_tree", doc::tree_io__write_tree)})
              .c_str())
      .def_property_readonly(
          "mesh", [](const PyHierarchy& self) { return PyMesh{self.hierarchy->shared_mesh()}; },
          "The mesh the tree was built on (shared, no copy).")
      .def_property_readonly(
          "face_count", [](const PyHierarchy& self) { return self.hierarchy->face_count(); },
          "F, the number of input faces: the length of every label array.")
      .def_property_readonly(
          "component_count",
          [](const PyHierarchy& self) { return self.hierarchy->component_count(); },
          "Connected components: the fewest clusters any cut gives.")
      .def_property_readonly(
          "primitives",
          [](const PyHierarchy& self) {
            py::tuple names(self.hierarchy->options().primitives.size());
            for (std::size_t i = 0; i < names.size(); ++i)
              names[i] = std::string(to_string(self.hierarchy->options().primitives[i]));
            return names;
          },
          doc::hierarchy__HierarchyOptions__primitives)
      .def_property_readonly(
          "weights",
          [](const PyHierarchy& self) {
            return self.hierarchy->options().weights == VertexWeights::Uniform ? "uniform" : "area";
          },
          doc::hierarchy__HierarchyOptions__weights)
      .def("__repr__",
           [](const PyHierarchy& self) {
             return "<primseg.Hierarchy: " + count_of(self.hierarchy->face_count(), "face") + ", " +
                    count_of(self.hierarchy->component_count(), "component") + ">";
           })
      .def("__copy__", [](const py::object& self) { return self; })
      .def("__deepcopy__", [](const py::object& self, const py::dict&) { return self; })
      // Pickled as its tree file (Hierarchy.save's bytes): for multiprocessing and joblib.
      .def(py::pickle(
          [](const PyHierarchy& self) {
            std::string bytes;
            {
              py::gil_scoped_release release;
              bytes = serialize_tree(*self.hierarchy);
            }
            return py::make_tuple(py::bytes(bytes));
          },
          [](const py::tuple& state) {
            if (state.size() != 1 || !py::isinstance<py::bytes>(state[0]))
              throw InvalidInputError("Hierarchy: not a pickled primseg.Hierarchy");
            // The bytes object outlives the read (the caller holds the state): no copy.
            const auto bytes = state[0].cast<std::string_view>();
            py::gil_scoped_release release;
            return PyHierarchy{std::make_shared<const Hierarchy>(
                deserialize_tree(bytes, "pickled primseg.Hierarchy"))};
          }));
}

}  // namespace primseg::python
