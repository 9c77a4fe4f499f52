#include <memory>

#include "command.hpp"
#include "limits.hpp"
#include "primseg/error.hpp"
#include "primseg/tree_io.hpp"

namespace primseg::cli {

Command add_cut_command(CLI::App& app) {
  struct Options {
    std::string tree_path;
    LevelOptions level;
    ResourceLimits limits;
  };
  auto o = std::make_shared<Options>();
  auto* cut_command = app.add_subcommand("cut", "Report a level of a saved hierarchy");
  cut_command
      ->add_option("TREE", o->tree_path,
                   "Tree file written by segment --tree (- for standard input)")
      ->required();
  add_level_options(*cut_command, o->level);
  add_fit_options(*cut_command, o->level);
  add_limit_options(*cut_command, o->limits, kMeshBytesPerFace);

  return {cut_command, [o] {
            if (!o->level.level.clusters && !o->level.level.tolerance)
              throw InvalidInputError(
                  "cut: give the level with --clusters K, --clusters auto or --tolerance T");
            validate_level_outputs(o->level);
            const auto read_start = Clock::now();
            std::uint64_t file_bytes = 0;
            const Hierarchy hierarchy =
                read_input_tree(o->tree_path, &file_bytes, o->limits.max_memory);
            check_mesh_limits({&hierarchy.mesh()}, file_bytes, o->limits,
                              o->level.files.png ? kPictureBytes : 0);
            validate_level(o->level.level, hierarchy.face_count());
            nlohmann::json summary;
            summary["mesh"] = mesh_summary(o->tree_path, hierarchy);
            summary["timing"] = {{"read_seconds", seconds_since(read_start)}};
            report_level(hierarchy, o->level, summary, Clock::now());
          }};
}

}  // namespace primseg::cli
