#pragma once
// One subcommand of the CLI: each lives in its own apps/<name>_command.cpp, registers its options
// on the parser and returns the action main() runs when the user chose it.

#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "level.hpp"
#include "outputs.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh.hpp"

namespace primseg::cli {

struct Command {
  CLI::App* parser = nullptr;  ///< the subcommand, owned by the top-level CLI::App
  std::function<void()> run;   ///< called after parsing when this subcommand was chosen
};

Command add_segment_command(CLI::App& app);
Command add_cut_command(CLI::App& app);
Command add_info_command(CLI::App& app);
Command add_eval_command(CLI::App& app);
Command add_batch_command(CLI::App& app);
Command add_denoise_command(CLI::App& app);
Command add_distance_command(CLI::App& app);
Command add_skeleton_command(CLI::App& app);
Command add_deform_command(CLI::App& app);
Command add_view_command(CLI::App& app);

// Helpers shared by the commands.

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start);

/// The input path that stands for standard input.
inline constexpr std::string_view kStandardInput = "-";

/// True for the path "-".
inline bool is_standard_input(const std::filesystem::path& path) {
  return path.native() == kStandardInput;
}

/// How messages name an input: its path, or "standard input" for "-".
std::string input_name(const std::filesystem::path& path);

/// A mesh named on the command line: the file `path` (its format from the extension), or standard
/// input when `path` is "-" (its format detected from the content: detect_mesh_format). `bytes`,
/// if set, receives the input's size. Throws as read_mesh; ParseError when standard input holds
/// no format primseg can tell, as soon as its first bytes show it (mesh_format_ruled_out: an
/// endless stream of anything else is not read to its end); InvalidInputError as soon as the
/// input has more bytes than `max_memory` (--max-memory), which bounds what a pipe, whose size
/// is unknown before its end, can make primseg read.
Mesh read_input_mesh(const std::filesystem::path& path, std::uint64_t* bytes = nullptr,
                     std::optional<std::uint64_t> max_memory = std::nullopt);

/// read_input_mesh(), then check_geometric_range(), whose message gets the input's name: the
/// commands that compute geometry read their meshes through this (`info` reads any finite
/// coordinates).
Mesh read_geometry(const std::filesystem::path& path, std::uint64_t* bytes = nullptr,
                   std::optional<std::uint64_t> max_memory = std::nullopt);

/// read_tree(path), or the tree on standard input for "-", whose read stops with
/// InvalidInputError as soon as the input has more bytes than `max_memory` (--max-memory);
/// `bytes`, if set, receives the input's size.
Hierarchy read_input_tree(const std::filesystem::path& path, std::uint64_t* bytes = nullptr,
                          std::optional<std::uint64_t> max_memory = std::nullopt);

/// The items of a comma-separated list, empty ones included ("" gives one empty item).
std::vector<std::string> split_comma_list(const std::string& list);

/// Parses "plane,sphere,cylinder" (fittable_types_from_list()); its InvalidInputError, naming
/// the unknown type and the available ones, starts with "--primitives: ".
std::vector<PrimitiveType> parse_primitives(const std::string& list);

/// A one-line progress indicator on stderr, only when stderr is a terminal and not --quiet.
class Progress {
 public:
  Progress(const char* what, bool quiet);
  void operator()(double fraction) const;

 private:
  const char* what_;
  bool enabled_;
};

/// The "mesh" entry of the JSON summary.
nlohmann::json mesh_summary(const std::string& file, const Hierarchy& hierarchy);

/// The options of --regularize as given on the command line. --relation-length-tolerance may be a
/// percentage of the bounding-box diagonal, so that one command line suits meshes of any size
/// (batch): it becomes a length for each mesh.
struct RelationChoice {
  RelationOptions options;             // all but the length tolerance, which is 0 here
  std::string length_tolerance = "0";  // --relation-length-tolerance L or L%
  /// The options for `mesh`, the length tolerance in its units.
  RelationOptions for_mesh(const Mesh& mesh) const;
};

/// A level (--clusters / --tolerance), the per-level output files and --quiet.
struct LevelOptions {
  LevelChoice level;
  OutputFiles files;
  std::uint32_t refine = 0;  // --refine N: boundary refinement passes after the cut
  bool regularize = false;   // --regularize: make the fits' relations exact and report them
  RelationChoice relations;  // --relation-significance, --max-relation-angle, ...
  bool quiet = false;
};

/// What `--clusters auto` means for segment and cut (choose_level).
inline constexpr std::string_view kChosenLevelRule =
    "the finest level after which the error curve jumps (x2), else its knee";

/// Adds --clusters (whose help says `auto_level` of 'auto'), --tolerance, the per-level output
/// files and --quiet to a command.
void add_level_options(CLI::App& command, LevelOptions& options,
                       std::string_view auto_level = kChosenLevelRule);
/// Adds --refine and --regularize (LevelOptions::refine and ::regularize) to a command that
/// reports a hierarchy's level, and the options of --regularize (add_relation_options).
void add_fit_options(CLI::App& command, LevelOptions& options);
/// Adds --merge-batch-tolerance (HierarchyOptions::merge_batch_tolerance) to a command that builds
/// a hierarchy.
void add_merge_batch_option(CLI::App& command, double& tolerance);
/// --regions N (HierarchyOptions::regions): the approximate merge order on several cores.
void add_regions_option(CLI::App& command, unsigned& regions);
/// Adds --relation-significance, --max-relation-angle, --relation-angle-tolerance,
/// --relation-length-tolerance and --max-radius-difference (the RelationOptions of --regularize),
/// checked by validate_relation_options() when the command runs.
void add_relation_options(CLI::App& command, RelationChoice& choice);
/// validate(RelationOptions), with the bound between two options named by their flags: throws
/// InvalidInputError.
void validate_relation_options(const RelationChoice& choice);
/// The options of `choice` that differ from the defaults, as " name=value" pairs (a resumed
/// batch redoes outputs made with others): empty for the defaults. A length tolerance in percent
/// is the text given.
std::string relation_options_signature(const RelationChoice& choice);

/// Checks the output names before any work (validate_output_files) and turns `quiet` on when an
/// output goes to standard output ('-'), which must then carry that output alone.
void validate_level_outputs(LevelOptions& options);

/// Cuts the chosen level and writes its outputs (and the tree when asked).
void report_level(const Hierarchy& hierarchy, const LevelOptions& options, nlohmann::json summary,
                  Clock::time_point cut_start);
/// The same for a level the command has already cut.
void report_level(const Hierarchy& hierarchy, const LevelOptions& options, ChosenLevel level,
                  nlohmann::json summary, Clock::time_point cut_start);

/// The JSON's "level" entry: `clusters`, and how the level was asked for and chosen.
nlohmann::json level_summary(const LevelOptions& options, const ChosenLevel& level,
                             std::uint32_t clusters);

}  // namespace primseg::cli
