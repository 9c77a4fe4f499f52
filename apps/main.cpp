// primseg: hierarchical segmentation of meshes into fitting primitives (command-line tool).
//
// Exit codes: 0 success, 1 bad input or usage (with a message on stderr), 2 internal error.
// Each subcommand lives in apps/<name>_command.cpp; this file only registers and dispatches.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <new>
#include <string>
#include <vector>

#include "../src/file_io.hpp"
#include "command.hpp"
#include "primseg/error.hpp"

namespace primseg::cli {
namespace {

int run(int argc, char** argv) {
  CLI::App app{
      "primseg: hierarchical segmentation of triangle meshes into planes, spheres and "
      "cylinders"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "primseg 0.1.0");

  // One command per line, so that adding one is a one-line change.
  // clang-format off
  const std::vector<Command> commands = {
      add_segment_command(app),
      add_cut_command(app),
      add_info_command(app),
      add_eval_command(app),
      add_batch_command(app),
      add_denoise_command(app),
      add_distance_command(app),
      add_skeleton_command(app),
      add_deform_command(app),
      add_view_command(app),
  };
  // clang-format on

  // Name an unknown command instead of CLI11's "A subcommand is required".
  if (argc > 1 && argv[1][0] != '-') {
    std::string known;
    bool found = false;
    for (const Command& command : commands) {
      known += (known.empty() ? "" : ", ") + command.parser->get_name();
      found |= command.parser->get_name() == argv[1];
    }
    if (!found)
      throw InvalidInputError("unknown command '" + std::string(argv[1]) + "' (commands: " + known +
                              ")");
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 1;
  }
  for (const Command& command : commands)
    if (*command.parser) command.run();
  return 0;
}

}  // namespace
}  // namespace primseg::cli

int main(int argc, char** argv) {
  // Ctrl-C leaves every output whole or absent (see the function).
  primseg::detail::defer_termination_during_writes();
  try {
    return primseg::cli::run(argc, argv);
  } catch (const primseg::Error& e) {
    std::fprintf(stderr, "primseg: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "primseg: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "primseg: internal error: %s\n", e.what());
    return 2;
  }
}
