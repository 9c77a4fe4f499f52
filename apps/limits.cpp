#include "limits.hpp"

#include <string>

#include "primseg/error.hpp"

namespace primseg::cli {
namespace {

std::uint64_t parse_byte_size(const std::string& text) {
  std::size_t used = 0;
  unsigned long long value = 0;
  try {
    value = std::stoull(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  std::uint64_t unit = 1;
  const std::string suffix = text.substr(used);
  if (suffix == "K" || suffix == "k")
    unit = 1ull << 10;
  else if (suffix == "M" || suffix == "m")
    unit = 1ull << 20;
  else if (suffix == "G" || suffix == "g")
    unit = 1ull << 30;
  else if (!suffix.empty())
    used = 0;
  if (used == 0 || text[0] == '-' || value == 0 || value > UINT64_MAX / unit)
    throw CLI::ValidationError("--max-memory",
                               "'" + text + "' is not a positive size (bytes, or N K, M or G)");
  return value * unit;
}

}  // namespace

void add_limit_options(CLI::App& command, ResourceLimits& limits) {
  command.add_option("--max-faces", limits.max_faces, "Refuse meshes with more input faces")
      ->check(CLI::PositiveNumber);
  command
      .add_option_function<std::string>(
          "--max-memory",
          [&limits](const std::string& text) { limits.max_memory = parse_byte_size(text); },
          "Refuse inputs whose estimated peak memory exceeds this (bytes, or with a K, M, G "
          "suffix; about 1 KB per face)")
      ->type_name("SIZE");
}

void check_mesh_limits(const Mesh& mesh, std::uint64_t file_bytes, const ResourceLimits& limits) {
  if (limits.max_faces && mesh.face_count() > *limits.max_faces)
    throw InvalidInputError("the mesh has " + std::to_string(mesh.face_count()) +
                            " faces, more than --max-faces " + std::to_string(*limits.max_faces));
  const std::uint64_t estimate = file_bytes + kBytesPerFace * mesh.face_count();
  if (limits.max_memory && estimate > *limits.max_memory)
    throw InvalidInputError("the mesh has " + std::to_string(mesh.face_count()) +
                            " faces, which need about " + std::to_string(estimate) +
                            " bytes, more than --max-memory " + std::to_string(*limits.max_memory));
}

}  // namespace primseg::cli
