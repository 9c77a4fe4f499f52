#pragma once
/// @file mesh_info.hpp
/// What `primseg info` prints: counts and defects of a mesh.

#include <cstdint>

#include "primseg/mesh.hpp"

namespace primseg {

struct MeshInfo {
  std::uint32_t vertices = 0;
  std::uint32_t faces = 0;                 ///< input faces (polygons)
  std::uint32_t triangles = 0;             ///< after triangulation
  std::uint32_t polygons = 0;              ///< input faces with more than 3 vertices
  std::uint32_t components = 0;            ///< edge-connected components
  std::uint32_t boundary_edges = 0;        ///< edges with one triangle
  std::uint32_t non_manifold_edges = 0;    ///< edges with three or more triangles
  std::uint32_t degenerate_triangles = 0;  ///< zero area
  std::uint32_t duplicate_triangles = 0;   ///< same vertex set as an earlier triangle
  std::uint32_t isolated_vertices = 0;     ///< in no face
  /// Edges of exactly two triangles that run along it the same way: triangles listed with
  /// inconsistent orientations (0 when every component is consistently oriented).
  std::uint32_t inconsistent_edges = 0;
  /// Closed components (every edge has exactly two triangles) listed consistently but facing
  /// inwards: negative signed volume. Readers that cull back faces show them inside out.
  std::uint32_t inward_components = 0;
  Vec3 bbox_min{0, 0, 0}, bbox_max{0, 0, 0};
  double bbox_diagonal = 0;
};

/// Counts in O(T log T).
MeshInfo describe_mesh(const Mesh& mesh);

}  // namespace primseg
