#pragma once
// --max-faces and --max-memory: bounds a service puts on one run, checked before the work they
// bound: the input's size by the read itself (read_input_mesh: a file's before it is read, a
// pipe's as it comes), the face count and the estimated peak before building.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>

#include "primseg/mesh.hpp"

namespace primseg::cli {

/// Peak memory of `segment` per input face, with a margin: measured with bench/scaling.sh (whole
/// process, 532 to 784 bytes per face from 1.2M down to 13k faces).
inline constexpr std::uint64_t kBytesPerFace = 1024;

struct ResourceLimits {
  std::optional<std::uint32_t> max_faces;  ///< refuse meshes with more input faces
  std::optional<std::uint64_t>
      max_memory;  ///< bytes; refuse inputs whose estimated peak exceeds it
};

/// Adds --max-faces and --max-memory (bytes, or with a K, M, G suffix: powers of 1024).
void add_limit_options(CLI::App& command, ResourceLimits& limits);

/// Throws InvalidInputError if the mesh exceeds --max-faces, or if the estimated peak of building
/// its hierarchy (file bytes + kBytesPerFace per face) exceeds --max-memory.
void check_mesh_limits(const Mesh& mesh, std::uint64_t file_bytes, const ResourceLimits& limits);

}  // namespace primseg::cli
