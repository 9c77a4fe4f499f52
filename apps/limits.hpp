#pragma once
// --max-faces and --max-memory: bounds a service puts on one run, checked before the work they
// bound: the input's size by the read itself (read_input_mesh: a file's before it is read, a
// pipe's as it comes), the face count and the estimated peak before the work.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <optional>

#include "primseg/mesh.hpp"

namespace primseg::cli {

// The peak memory --max-memory's estimate uses: kProcessBytes + the input files' bytes + the
// command's bytes per input triangle (face, on the triangle meshes measured), with a margin over
// the peak RSS measured on fandisk, bunny00 and bunny00 midpoint-subdivided to 302k and 1.2M faces
// (figures below: whole process, per face).

/// The process before any input: 5 to 6 MB.
inline constexpr std::uint64_t kProcessBytes = 8ull << 20;
/// A --png picture's buffers (800 x 600, supersampled), whatever the mesh: 16 MB.
inline constexpr std::uint64_t kPictureBytes = 24ull << 20;
/// view's page: the viewer's code and the JSON of the tree, levels and skeleton it embeds (the
/// per-face part is in kViewBytesPerFace).
inline constexpr std::uint64_t kViewerPageBytes = 24ull << 20;
/// segment, batch, skeleton: 542 to 933 bytes per face; --regions 2 on two threads, whose two
/// regions' builds overlap the whole mesh's graph: 606 to 1,036 (fandisk's within the 8 MiB every
/// estimate adds).
inline constexpr std::uint64_t kHierarchyBytesPerFace = 1024;
/// view (with --skeleton): 807 to 2,821 bytes per face, kViewerPageBytes included.
inline constexpr std::uint64_t kViewBytesPerFace = 1280;
/// denoise: a second copy of the mesh to segment, refits and, with --iterations, a tree per
/// round: 764 to 1,207 bytes per face, 1,424 with two rounds on fandisk.
inline constexpr std::uint64_t kDenoiseBytesPerFace = 1536;
/// denoise --ensemble on two threads or more, which builds two members' hierarchies at once and
/// keeps up to three ahead of its snaps: 1,870 to 2,400 bytes per face (fandisk, bunny00; 1,160 to
/// 1,250 on one thread).
inline constexpr std::uint64_t kDenoiseEnsembleBytesPerFace = 3072;
/// info, distance (per face of both meshes), deform, cut (beside its tree file's bytes): the mesh
/// and its adjacency, search tree, skinning weights or level: 222 to 633 bytes per face, 130 to
/// 400 per face of distance's two meshes, 339 to 748 for cut (its tree file has 154 per face).
inline constexpr std::uint64_t kMeshBytesPerFace = 512;
/// info --noise: a smoothed copy of the mesh, each face's neighbourhood, normals and centroids:
/// 433 to 810 bytes per face (bunny00 midpoint-subdivided to 1.2M faces, fandisk).
inline constexpr std::uint64_t kNoiseEstimateBytesPerFace = 1024;

struct ResourceLimits {
  std::optional<std::uint32_t> max_faces;  ///< refuse meshes with more input faces
  std::optional<std::uint64_t>
      max_memory;  ///< bytes; refuse inputs whose estimated peak exceeds it
  std::uint64_t bytes_per_face = kHierarchyBytesPerFace;  ///< the command's peak per triangle
};

/// Adds --max-faces and --max-memory (bytes, or with a K, M, G suffix: powers of 1024) to a
/// command whose peak is about `bytes_per_face` per input face (kept in `limits`).
void add_limit_options(CLI::App& command, ResourceLimits& limits, std::uint64_t bytes_per_face);

/// Throws InvalidInputError if a mesh exceeds --max-faces, or if the estimated peak of the run
/// (kProcessBytes + the input files' bytes + bytes_per_face per triangle of all the meshes +
/// `fixed_bytes`, buffers whatever the mesh: kPictureBytes for a --png) exceeds --max-memory.
/// Per triangle: a face of n corners is n - 2 triangles.
void check_mesh_limits(std::initializer_list<const Mesh*> meshes, std::uint64_t file_bytes,
                       const ResourceLimits& limits, std::uint64_t fixed_bytes = 0);

/// read_geometry(path), its read stopped past --max-memory, then check_mesh_limits().
Mesh read_geometry_within(const std::filesystem::path& path, const ResourceLimits& limits,
                          std::uint64_t fixed_bytes = 0);

}  // namespace primseg::cli
