#include "limits.hpp"

#include <cstdio>
#include <string>

#include "command.hpp"
#include "outputs.hpp"
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

void add_limit_options(CLI::App& command, ResourceLimits& limits, std::uint64_t bytes_per_face) {
  limits.bytes_per_face = bytes_per_face;
  command.add_option("--max-faces", limits.max_faces, "Refuse meshes with more input faces")
      ->check(CLI::PositiveNumber);
  const double kilobytes = static_cast<double>(bytes_per_face) / 1024;
  char per_face[32];
  std::snprintf(per_face, sizeof per_face, "%g", kilobytes);
  command
      .add_option_function<std::string>(
          "--max-memory",
          [&limits](const std::string& text) { limits.max_memory = parse_byte_size(text); },
          "Refuse inputs whose estimated peak memory exceeds this (bytes, or with a K, M, G "
          "suffix; about " +
              std::string(per_face) + " KB per face)")
      ->type_name("SIZE");
}

void check_mesh_limits(std::initializer_list<const Mesh*> meshes, std::uint64_t file_bytes,
                       const ResourceLimits& limits, std::uint64_t fixed_bytes) {
  std::uint64_t faces = 0, triangles = 0;
  for (const Mesh* mesh : meshes) {
    if (limits.max_faces && mesh->face_count() > *limits.max_faces)
      throw InvalidInputError("the mesh has " + count_of(mesh->face_count(), "face") +
                              ", more than --max-faces " + std::to_string(*limits.max_faces));
    faces += mesh->face_count();
    triangles += mesh->triangle_count();
  }
  // Per triangle: a polygon of n vertices is one face, but n - 2 triangles to store and read.
  const std::uint64_t estimate =
      kProcessBytes + fixed_bytes + file_bytes + limits.bytes_per_face * triangles;
  if (limits.max_memory && estimate > *limits.max_memory)
    throw InvalidInputError(
        (meshes.size() == 1 ? "the mesh has " : "the meshes have ") + count_of(faces, "face") +
        (triangles > faces ? " (" + count_of(triangles, "triangle") + ")" : "") +
        (meshes.size() == 1 ? "" : " in all") + ", which need about " + std::to_string(estimate) +
        " bytes, more than --max-memory " + std::to_string(*limits.max_memory));
}

Mesh read_geometry_within(const std::filesystem::path& path, const ResourceLimits& limits,
                          std::uint64_t fixed_bytes) {
  std::uint64_t file_bytes = 0;
  Mesh mesh = read_geometry(path, &file_bytes, limits.max_memory);
  check_mesh_limits({&mesh}, file_bytes, limits, fixed_bytes);
  return mesh;
}

}  // namespace primseg::cli
