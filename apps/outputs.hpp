#pragma once
// The per-level outputs shared by `segment` and `cut`: labels, JSON, coloured mesh, summary.

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "../src/json_document.hpp"
#include "primseg/cut.hpp"
#include "primseg/relations.hpp"

namespace primseg::cli {

/// The output name that stands for standard output. Only the text outputs (labels, json, linkage,
/// curve) accept it, one at a time; a file literally named '-' is still reachable as ./-.
inline constexpr std::string_view kStandardOutput = "-";

struct OutputFiles {
  std::optional<std::string> labels;   // one label per line, per input face
  std::optional<std::string> json;     // clusters with primitives, and their borders
  std::optional<std::string> borders;  // border curves as OBJ polylines
  std::optional<std::string> colored;  // .ply (face colours) or .obj (groups)
  std::optional<std::string> tree;     // whole hierarchy (segment only)
  std::optional<std::string> png;      // picture of the clusters
  std::optional<std::string> linkage;  // SciPy linkage matrix of the whole tree, as text
  std::optional<std::string> curve;    // error curve of the whole tree, CSV k,rms
};

/// A count and its noun for messages: "1 cluster", "2 clusters"; `plural` for irregular nouns
/// ("vertices").
std::string count_of(std::uint64_t count, std::string_view noun, std::string_view plural = {});

/// Throws InvalidInputError for output names that cannot be written (checked before any work):
/// a coloured mesh that is neither .ply nor .obj, borders not in .obj, '-' for a binary output,
/// or '-' twice.
void validate_output_files(const OutputFiles& files);

/// True when an output (a text one, or the tree) goes to standard output: the command must then
/// print nothing else there (its summary is suppressed as by --quiet).
bool writes_to_standard_output(const OutputFiles& files);

/// Writes `bytes` (text, or the tree file) to the file `path` atomically, or to standard output
/// when `path` is "-". Throws IoError.
void write_output(const std::string& path, std::string_view bytes);

// JSON documents with large arrays, and points as JSON (src/json_document.hpp).
using detail::dump_document;
using detail::StreamedArray;
using detail::vec3_json;

/// JSON parameters of a primitive, input units.
nlohmann::json primitive_params(const Primitive& primitive);

/// Writes the requested per-level files: those of a level (`labels`, shape (F), and its
/// clusters' `reports`) on `mesh`, which the coloured mesh, the picture and the border curves
/// show (the hierarchy's mesh, or a mesh with its connectivity), and those of the whole
/// `hierarchy` (the linkage and the error curve). `summary` holds the JSON's other entries.
void write_level_outputs(const Hierarchy& hierarchy, const Mesh& mesh,
                         std::span<const std::uint32_t> labels,
                         const std::vector<ClusterReport>& reports, const OutputFiles& files,
                         const nlohmann::json& summary);

/// The JSON's "relations": [{"kind": "parallel", "clusters": [0, 3]}, ...].
nlohmann::json relations_json(const std::vector<ClusterRelation>& relations);

/// A short human-readable table of the largest clusters, then the relations, on stdout.
void print_summary(const std::vector<ClusterReport>& reports,
                   const std::vector<ClusterRelation>& relations = {}, std::size_t max_rows = 12);

}  // namespace primseg::cli
