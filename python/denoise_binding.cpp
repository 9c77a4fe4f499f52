// denoise(): `primseg denoise`, the vertices snapped onto the primitives of a level, round after
// round.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "binding_support.hpp"
#include "bindings.hpp"
#include "doxygen_docstrings.hpp"
#include "primseg/auto_level.hpp"
#include "primseg/bilateral_smoothing.hpp"
#include "primseg/borders.hpp"
#include "primseg/cut.hpp"
#include "primseg/denoise.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"

namespace primseg::python {
namespace {

py::dict snap_report_dict(const SnapReport& r) {
  py::dict round;
  round["clusters"] = r.clusters;
  round["boundary_vertices"] = r.boundary_vertices;
  round["snapped"] = r.snapped;
  round["moved"] = r.moved;
  round["fallbacks"] = r.fallbacks;
  round["blocked"] = r.blocked;
  round["mean_move"] = r.mean_move;
  round["max_move"] = r.max_move;
  round["ensemble_members"] = r.ensemble_members;
  round["reverted"] = r.reverted;
  return round;
}

}  // namespace

void bind_denoise(py::module_& m) {
  const char* denoise_doc =
      R"(denoise(mesh, *, k=None, tolerance=None, relative_tolerance=None, iterations=1, smoothing_steps=0, bilateral=False, stylize=False, max_move=4.0, min_crease_angle=10.0, relabel_passes=2, relation_significance=3.0, noise_tolerance_factor=None, ensemble=1, ensemble_jitter=0.3, primitives=None, weights=None, threads=0, regions=1, return_rounds=False, return_level=False, progress=None) -> numpy.ndarray
denoise(V, F, *, ...) -> numpy.ndarray
denoise(hierarchy, *, ...) -> numpy.ndarray

`primseg denoise`: snaps every vertex onto the primitives of a level, `iterations` times (each
round segments the previous round's result), and returns the new positions, float64 (n, 3), in
the input's vertex order (the faces do not change): the CLI's output mesh, bit for bit. With
return_rounds=True it returns (V, rounds), rounds a list of dicts like the CLI's --json
"denoise" "rounds" (clusters, boundary_vertices, snapped, moved, fallbacks, blocked, mean_move,
max_move, ensemble_members, reverted). With return_level=True it returns (V, level), or (V, rounds, level) with both: the
last round's snap (Denoiser::snapped_level) as a dict of "labels" (int32 (F,), the CLI's
--labels), "clusters", "borders" and "relations" (the CLI's --json entries: the clusters after
relabelling with the primitives the vertices went onto, their borders on the denoised mesh, and
the groups of clusters made parallel or coaxial, {kind, clusters}); with k="auto" also how the
level was chosen, as the CLI's --json "level" says it: "rule" ("jump", "knee", ... or "noise"
for the tolerance cut) and, without stylize, "noise_estimate" and "noise_tolerance" (input
units) and, when the curve jumps, "jump_worst_rms" (its worst cluster's RMS).
The input is a Mesh, arrays V and F (as segment takes them), or a Hierarchy: its first round
then snaps onto that tree's level without building it again (smoothing_steps must be 0, and the
later rounds use its primitives and weights).
Level: k (count or "auto"), tolerance or relative_tolerance as in Hierarchy.cut, the CLI's
--clusters and --tolerance; none: 0.1% of the diagonal. k="auto" is denoising's automatic level
(Denoiser::automatic_level): a jump of the error curve whose clusters each fit within 4.5
times that tolerance, else the clusters within a multiple of the estimated noise
(noise_tolerance_factor: None for the default of the segmented copy).
stylize: --stylize (each vertex onto its own cluster's primitive); max_move: --max-move (in mean
incident edge lengths); min_crease_angle: --min-crease-angle (degrees); relabel_passes:
--relabel-passes (faces moved to the nearest refitted neighbouring primitive);
relation_significance: --relation-significance (0: no parallel or coaxial relations); smoothing_steps:
--smooth (Taubin steps on the copy that is segmented); bilateral: --bilateral (that copy
smoothed by bilateral normal filtering instead, which keeps edges sharp); ensemble and
ensemble_jitter: --ensemble (the mean of the snaps onto that many hierarchies, the further ones
built on jittered copies; progress then advances, and Ctrl-C is checked, as each is built) and
--ensemble-jitter (in estimated noise deviations); primitives (default plane, cylinder, sphere) and weights (default "area"): as in
segment; regions: --regions, as in segment (each round's hierarchy in the approximate order). The GIL is released while it works; as in segment, Ctrl-C (KeyboardInterrupt) stops a
round's hierarchy build, and progress, if given, is called during the builds with the fraction
of all rounds done (0 to 1).
Raises InvalidInputError (a ValueError) for bad arrays or options out of range.)";
  m.def(
      "denoise",
      [](const py::object& first, const py::object& faces, ClusterCount k,
         std::optional<double> tolerance, std::optional<double> relative_tolerance, int iterations,
         int smoothing_steps, bool bilateral, bool stylize, double max_move,
         double min_crease_angle, int relabel_passes, double relation_significance,
         std::optional<double> noise_tolerance_factor, int ensemble, double ensemble_jitter,
         const py::object& primitives, const py::object& weights, unsigned threads,
         unsigned regions, bool return_rounds, bool return_level,
         const py::object& progress) -> py::object {
        const LevelArguments level{std::move(k), tolerance, relative_tolerance};
        const PyHierarchy* given =
            py::isinstance<PyHierarchy>(first) ? &first.cast<const PyHierarchy&>() : nullptr;
        if (given && !faces.is_none())
          throw InvalidInputError("denoise(hierarchy) takes no F (give the level as k=...)");
        if (relabel_passes < 0 || relabel_passes > 100)
          throw InvalidInputError(
              "relabel_passes must be between 0 and 100 (the CLI's range), not " +
              std::to_string(relabel_passes));
        DenoiseOptions options;
        options.mode = stylize ? SnapMode::NearestIncident : SnapMode::AllIncident;
        options.max_move_edge_lengths = max_move;
        options.min_crease_angle_degrees = min_crease_angle;
        options.relabel_passes = relabel_passes;
        options.relation_significance = relation_significance;
        options.noise_tolerance_factor = noise_tolerance_factor;
        options.ensemble_members = ensemble;
        options.ensemble_jitter = ensemble_jitter;
        options.smoothing_steps = smoothing_steps;
        if (bilateral) options.bilateral_smoothing = BilateralSmoothingOptions{};
        options.hierarchy =
            tool_hierarchy_options("denoise", given, primitives, weights, threads, regions,
                                   py::make_tuple("plane", "cylinder", "sphere"));
        validate(options);
        if (iterations < 1 || iterations > 100)
          throw InvalidInputError("iterations must be between 1 and 100 (the CLI's range), not " +
                                  std::to_string(iterations));
        if (smoothing_steps < 0 || smoothing_steps > 1000)
          throw InvalidInputError(
              "smoothing_steps must be between 0 and 1000 (the CLI's range), not " +
              std::to_string(smoothing_steps));
        if (given && (smoothing_steps > 0 || bilateral))
          throw InvalidInputError(
              "denoise(hierarchy): smoothing_steps must be 0 and bilateral False (the tree was "
              "built on the mesh as it is); give the mesh to segment a smoothed copy");
        const std::shared_ptr<const Mesh> mesh =
            given ? given->hierarchy->shared_mesh() : mesh_argument("denoise", first, faces);
        validate_level(level, mesh->face_count());
        const std::function<void(double)> progress_of_all = python_progress(progress);
        std::vector<SnapReport> reports;
        std::vector<Vec3> positions;
        SnappedLevel snapped;
        std::vector<ClusterBorder> borders;
        // k="auto": denoising's own automatic level, as `primseg denoise --clusters auto`.
        const bool automatic = level.k && std::holds_alternative<std::string>(*level.k);
        DenoiseLevel chosen;  // the last round's, when automatic
        without_gil([&] {
          Denoiser denoiser(*mesh, options);
          for (int round = 0; round < iterations; ++round) {
            // As `primseg denoise`: each round segments the previous round's result.
            // The ensemble's members share the round: each reports when its hierarchy is built
            // (where Ctrl-C is checked), the first during its build too.
            int member = 0;
            const auto report_round = [&](double fraction) {
              progress_of_all((round + (member + fraction) / options.ensemble_members) /
                              iterations);
            };
            const std::shared_ptr<const Hierarchy> hierarchy =
                round == 0 && given
                    ? given->hierarchy
                    : std::make_shared<const Hierarchy>(
                          HierarchyBuilder(denoiser.segmented_mesh(), options.hierarchy)
                              .finish(report_round));
            if (automatic) chosen = denoiser.automatic_level(*hierarchy);
            reports.push_back(denoiser.snap(
                *hierarchy, automatic ? chosen.segmentation : cut_level(*hierarchy, level),
                [&](const Hierarchy& jittered) {
                  ++member;
                  report_round(0);
                  return automatic ? denoiser.automatic_level(jittered).segmentation
                                   : cut_level(jittered, level);
                }));
            if (options.ensemble_members > 1) progress_of_all((round + 1.0) / iterations);
          }
          if (return_level) {
            snapped = denoiser.snapped_level();
            borders = cluster_borders(denoiser.mesh(), snapped.labels,
                                      cluster_primitives(snapped.clusters));
          }
          positions = denoiser.mesh().positions;
        });
        py::array V = positions_array(std::move(positions));
        if (!return_rounds && !return_level) return V;
        py::list result;
        result.append(V);
        if (return_rounds) {
          py::list rounds;
          for (const SnapReport& report : reports) rounds.append(snap_report_dict(report));
          result.append(rounds);
        }
        if (return_level) {
          py::dict snapped_dict;
          py::list clusters, border_list;
          for (const ClusterReport& report : snapped.clusters)
            clusters.append(cluster_dict(report));
          for (const ClusterBorder& border : borders) border_list.append(border_dict(border));
          const auto face_count = static_cast<py::ssize_t>(snapped.labels.size());
          snapped_dict["labels"] = adopt<std::int32_t>(std::move(snapped.labels), {face_count});
          snapped_dict["clusters"] = clusters;
          snapped_dict["borders"] = border_list;
          snapped_dict["relations"] = relations_list(snapped.relations);
          // How k="auto" chose, with the keys and values of the CLI's --json "level".
          if (automatic) {
            snapped_dict["rule"] =
                chosen.by_noise ? "noise" : std::string(to_string(chosen.automatic.rule));
            if (!stylize) {
              snapped_dict["noise_estimate"] = chosen.noise;
              snapped_dict["noise_tolerance"] = chosen.tolerance;
              if (chosen.automatic.rule == AutoLevelRule::Jump)
                snapped_dict["jump_worst_rms"] = chosen.jump_worst_rms;
            }
          }
          result.append(snapped_dict);
        }
        return py::tuple(result);
      },
      py::arg("mesh_or_V"), py::arg("F") = py::none(), py::kw_only(), py::arg("k") = py::none(),
      py::arg("tolerance") = py::none(), py::arg("relative_tolerance") = py::none(),
      py::arg("iterations") = 1, py::arg("smoothing_steps") = DenoiseOptions{}.smoothing_steps,
      py::arg("bilateral") = false, py::arg("stylize") = false,
      py::arg("max_move") = DenoiseOptions{}.max_move_edge_lengths,
      py::arg("min_crease_angle") = DenoiseOptions{}.min_crease_angle_degrees,
      py::arg("relabel_passes") = DenoiseOptions{}.relabel_passes,
      py::arg("relation_significance") = DenoiseOptions{}.relation_significance,
      py::arg("noise_tolerance_factor") = py::none(),
      py::arg("ensemble") = DenoiseOptions{}.ensemble_members,
      py::arg("ensemble_jitter") = DenoiseOptions{}.ensemble_jitter,
      py::arg("primitives") = py::none(), py::arg("weights") = py::none(), py::arg("threads") = 0u,
      py::arg("regions") = 1u, py::arg("return_rounds") = false, py::arg("return_level") = false,
      py::arg("progress") = py::none(),
      join_docs(
          {denoise_doc, cpp_doc("denoise.hpp", doc::denoise__file),
           cpp_doc("DenoiseOptions::max_move_edge_lengths",
                   doc::denoise__DenoiseOptions__max_move_edge_lengths),
           cpp_doc("DenoiseOptions::min_crease_angle_degrees",
                   doc::denoise__DenoiseOptions__min_crease_angle_degrees),
           cpp_doc("DenoiseOptions::relabel_passes", doc::denoise__DenoiseOptions__relabel_passes),
           cpp_doc("DenoiseOptions::relation_significance",
                   doc::denoise__DenoiseOptions__relation_significance),
           cpp_doc("DenoiseOptions::noise_tolerance_factor",
                   doc::denoise__DenoiseOptions__noise_tolerance_factor),
           cpp_doc("DenoiseOptions::smoothing_steps",
                   doc::denoise__DenoiseOptions__smoothing_steps),
           cpp_doc("DenoiseOptions::bilateral_smoothing",
                   doc::denoise__DenoiseOptions__bilateral_smoothing),
           cpp_doc("DenoiseOptions::ensemble_members",
                   doc::denoise__DenoiseOptions__ensemble_members),
           cpp_doc("DenoiseOptions::ensemble_jitter",
                   doc::denoise__DenoiseOptions__ensemble_jitter),
           cpp_doc("SnapMode", doc::denoise__SnapMode),
           cpp_doc("SnapReport", doc::denoise__SnapReport),
           cpp_doc("SnappedLevel", doc::denoise__SnappedLevel)})
          .c_str());
}

}  // namespace primseg::python
