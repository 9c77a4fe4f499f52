#pragma once
/// @file mesh.hpp
/// The mesh primseg works on: input polygons, kept for output, and their triangulation, on which
/// every computation runs.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace primseg {

using Vec3 = std::array<double, 3>;
using Triangle = std::array<std::uint32_t, 3>;

/// A polygon mesh and its triangulation.
///
/// Invariants (established by the readers and by Mesh::from_polygons, checked by validate()):
/// - every coordinate is finite;
/// - `polygon_offsets` has face_count() + 1 entries, starts at 0 and is non-decreasing by at
///   least 3 per face; `polygon_vertices` indexes `positions`;
/// - `triangles` index `positions`; `face_of_triangle[t]` is the input face triangle t came from,
///   non-decreasing in t, and every input face has at least one triangle.
/// Zero-area faces, duplicate faces, non-manifold edges, isolated vertices and several connected
/// components are all allowed.
struct Mesh {
  /// Vertex positions, shape (n, 3), in input units.
  std::vector<Vec3> positions;
  /// Input faces (polygons) as offsets into polygon_vertices, shape (F + 1).
  std::vector<std::uint32_t> polygon_offsets{0};
  /// Concatenated vertex loops of the input faces.
  std::vector<std::uint32_t> polygon_vertices;
  /// Triangulation of the input faces, shape (T, 3), same orientation as their polygon.
  std::vector<Triangle> triangles;
  /// Input face of each triangle, shape (T).
  std::vector<std::uint32_t> face_of_triangle;

  /// Number of input faces F (polygons). Every per-face output has this many entries.
  std::uint32_t face_count() const {
    return static_cast<std::uint32_t>(polygon_offsets.size() - 1);
  }
  std::uint32_t vertex_count() const { return static_cast<std::uint32_t>(positions.size()); }
  std::uint32_t triangle_count() const { return static_cast<std::uint32_t>(triangles.size()); }
  /// Vertex loop of input face f (f < face_count(), not checked).
  std::span<const std::uint32_t> polygon(std::uint32_t f) const {
    return {polygon_vertices.data() + polygon_offsets[f],
            polygon_vertices.data() + polygon_offsets[f + 1]};
  }

  /// Builds a mesh from positions and polygons (each of at least 3 vertices), triangulating every
  /// polygon of more than three vertices by ear clipping in its best-fit plane (fan fallback).
  /// Throws InvalidInputError on a non-finite coordinate, an out-of-range index or a polygon
  /// with fewer than 3 vertices.
  static Mesh from_polygons(std::vector<Vec3> positions, std::vector<std::uint32_t> offsets,
                            std::vector<std::uint32_t> vertices);
  /// Builds a mesh from triangles; same checks as from_polygons.
  static Mesh from_triangles(std::vector<Vec3> positions, std::vector<Triangle> triangles);

  /// Throws InvalidInputError if an invariant above does not hold.
  void validate() const;
};

/// Axis-aligned bounding box diagonal length of the vertices used by some face (0 for no faces).
double bounding_box_diagonal(const Mesh& mesh);
/// Centre of that box, input units ((0, 0, 0) for no faces).
Vec3 bounding_box_centre(const Mesh& mesh);

/// Largest coordinate magnitude the geometric operations accept (input units). Some of them work
/// in input units with fourth powers of lengths (area-weighted second moments) and their squares:
/// those stay normal doubles from kMinPositiveExtent to here, so that results do not depend on the
/// units: scaling a mesh by a power of two scales every result exactly (fuzz/tools_fuzzer.cpp),
/// but for round-off zeros that underflow below the normal doubles, which only stay as tiny.
inline constexpr double kMaxCoordinateMagnitude = 1e32;
/// Smallest extent (largest side of the bounding box of the vertices used by some face, input
/// units) the geometric operations accept, other than 0 (every face collapsed to one point): see
/// kMaxCoordinateMagnitude.
inline constexpr double kMinPositiveExtent = 1e-32;

/// Throws InvalidInputError naming the problem when a valid mesh's coordinates are outside the
/// range the geometric operations compute with in input units (hierarchy, denoising, smoothing,
/// distances): a coordinate of magnitude above kMaxCoordinateMagnitude, or a positive extent
/// below kMinPositiveExtent. Reading and writing meshes accept every finite coordinate; this is
/// checked where the geometry starts.
void check_geometric_range(const Mesh& mesh);

}  // namespace primseg
