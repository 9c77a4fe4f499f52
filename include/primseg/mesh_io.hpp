#pragma once
/// @file mesh_io.hpp
/// Reading and writing meshes: OFF, OBJ, PLY (ascii, binary little and big endian) and STL (ascii
/// and binary). Readers never trust a header count further than the file size allows and report
/// every failure as a ParseError naming the file and the line (text) or byte offset (binary).

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <string_view>

#include "primseg/mesh.hpp"

namespace primseg {

enum class MeshFormat { Off, Obj, Ply, Stl };

/// Format from the file extension (case-insensitive: .off .obj .ply .stl). Throws
/// InvalidInputError naming the path for any other extension.
MeshFormat mesh_format_from_path(const std::filesystem::path& path);

/// Reads a mesh file, choosing the reader by extension. Polygons are triangulated (Mesh invariants
/// hold); STL triangle soups are welded by exact coordinate match.
/// Throws IoError (cannot open/read), ParseError (malformed, truncated, counts that do not match,
/// indices out of range, unparsable tokens, empty file), InvalidInputError (NaN/inf coordinates,
/// no faces).
Mesh read_mesh(const std::filesystem::path& path);

/// Reads a mesh from an in-memory file image. `name` is only used in error messages.
Mesh read_mesh(std::span<const char> bytes, MeshFormat format, std::string_view name = "<memory>");

/// detect_mesh_format() reads text signatures (a first token after comment lines) from at most
/// this many first bytes (64 KiB).
inline constexpr std::size_t kMeshSignatureBytes = std::size_t{64} << 10;

/// Format from the content of a file image, for data without a trustworthy extension (uploads,
/// pipes): "ply" on the first line; a first token (after '#' comment lines) of the OFF family
/// (OFF, COFF, NOFF, STOFF, ...); a binary STL whose size matches its triangle count, or text
/// starting with "solid"; a first token that is an OBJ statement (v, vt, vn, f, o, g, s, l,
/// mtllib, usemtl). Empty when none applies.
std::optional<MeshFormat> detect_mesh_format(std::span<const char> bytes);

/// For data that arrives in pieces (a pipe): true when its first bytes, `prefix`, already rule out
/// every format detect_mesh_format() could find in the whole data, if the data has at most
/// `max_size` bytes, whatever follows. Text signatures are read from the first kMeshSignatureBytes,
/// a binary STL is told by its size: true once `prefix` holds that many or more without a text
/// signature, and
/// the binary STL its first 84 bytes would declare is shorter than `prefix` or longer than
/// `max_size` (say, what the reader can hold). A reader can then stop at once instead of at the
/// end of the data.
bool mesh_format_ruled_out(std::span<const char> prefix,
                           std::uint64_t max_size = std::numeric_limits<std::uint64_t>::max());

/// Reads a mesh whose format is detected from its content (detect_mesh_format). Throws
/// ParseError naming `name` when the format cannot be told, else as read_mesh.
Mesh read_mesh_detecting_format(std::span<const char> bytes, std::string_view name = "<memory>");

/// What write_mesh writes besides the geometry.
struct MeshWriteOptions {
  /// Optional group (cluster) of each input face, shape (F). Empty: no groups.
  /// PLY: faces get the group's colour as uchar red/green/blue properties; OBJ: one `g
  /// cluster_<id>` statement per group, faces grouped by id; OFF: per-face RGB colours; STL:
  /// ignored.
  std::span<const std::uint32_t> face_groups;
  /// Colour of each group, shape (largest group id + 1). Empty with groups: the built-in colours
  /// of group_face_colors().
  std::span<const std::array<std::uint8_t, 3>> group_colors;
  /// PLY and STL: binary little-endian (true) or ascii (false).
  bool binary = true;
};

/// Writes the mesh's input polygons (STL: its triangles) in the format given by the extension.
/// The file is written to a temporary name beside the target and renamed into place, so an
/// interrupted run never leaves a partial file. Throws IoError, InvalidInputError.
void write_mesh(const std::filesystem::path& path, const Mesh& mesh,
                const MeshWriteOptions& options = {});

/// A palette of `count` distinct, well-separated RGB colours (deterministic; each palette begins
/// with the shorter ones).
std::vector<std::array<std::uint8_t, 3>> distinct_colors(std::size_t count);

/// The colour of each face of a labelling (one group id per face, shape (F)), as write_mesh, the
/// CLI's --colored and --png and the Python module draw clusters: distinct_colors()[k] for group
/// k, the same in every picture, while the ids are below F (as any segmentation's are); larger
/// ids are numbered by rank first, so that the palette never outgrows the mesh. Shape (F).
std::vector<std::array<std::uint8_t, 3>> group_face_colors(
    std::span<const std::uint32_t> face_groups);

}  // namespace primseg
