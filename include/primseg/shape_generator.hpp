#pragma once
/// @file shape_generator.hpp
/// CAD-like test solids with known ground-truth segmentation: every face is labelled with the
/// analytic primitive (plane, cylinder, sphere, cone, torus) it was sampled from.
///
/// Shapes are closed, manifold and consistently outward-oriented, and every ground-truth region
/// is edge-connected. Vertices along a boundary between two regions are shared by both, so the
/// triangulation is conforming. Output is deterministic: the same name and options give a
/// bit-identical mesh on a given platform.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "primseg/mesh.hpp"
#include "primseg/primitive.hpp"

namespace primseg {

/// How a shape's surfaces are triangulated.
enum class Tessellation {
  /// As CAD exporters do: planar faces with as few triangles as possible (no interior
  /// vertices, hence long thin triangles), curved surfaces as strips between rings of
  /// ShapeOptions::segments vertices (a cylinder is one strip between its two end circles).
  Cad,
  /// Near-equilateral triangles of roughly ShapeOptions::edge_length everywhere, conforming
  /// across region boundaries.
  Uniform,
};

/// Parameters of make_shape().
struct ShapeOptions {
  Tessellation tessellation = Tessellation::Cad;
  /// Uniform only: target edge length, as a fraction of the shape's bounding-box diagonal.
  /// Must be in (0, 1].
  double edge_length = 0.05;
  /// Cad only: number of segments of a full circle (at least 3). Arcs and the latitude bands of
  /// spheres use the same angular step.
  int segments = 48;
  /// Standard deviation of Gaussian noise added to each vertex along its area-weighted vertex
  /// normal, as a fraction of the bounding-box diagonal (0 = exact). Labels and primitives are
  /// those of the noise-free shape.
  double noise = 0.0;
  /// Apply a random rotation, translation (each coordinate in [-5, 5]) and uniform scale
  /// (log-uniform in [0.1, 10]) to the shape and its primitives.
  bool random_motion = false;
  /// Seed of the motion and of the noise (independent streams).
  std::uint64_t seed = 1;
};

/// A generated shape and its ground truth.
struct GroundTruthShape {
  std::string name;
  /// The mesh; every face is a triangle (face_of_triangle is the identity). Closed, manifold,
  /// outward-oriented and edge-connected.
  Mesh mesh;
  /// Ground-truth region of each face, shape (F), values in 0..R-1.
  std::vector<std::uint32_t> region_of_face;
  /// Analytic primitive of each region, shape (R), in the final (moved) frame and in the
  /// canonical form of primitive.hpp: a plane's point is the area-weighted centroid of its
  /// noise-free region and its axis the outward unit normal; a cylinder's axis has its
  /// largest-magnitude component positive and its point is the region's area-weighted centroid
  /// projected on the axis; a sphere is its centre and radius; a cone its apex, unit axis from the
  /// apex into the cone and half-angle; a torus its centre, unit axis (largest-magnitude
  /// component positive), major and minor radius. Lengths in mesh units.
  std::vector<Primitive> regions;
};

/// Names of the catalogue, in a fixed order:
/// - `box`: 6 planes;
/// - `slanted_box`: a box with one corner cut off by a slanted plane, 7 planes;
/// - `capped_cylinder`: cylinder and its 2 end discs;
/// - `sphere`: 1 sphere (Cad: UV sphere; Uniform: projected subdivided icosahedron);
/// - `box_with_hole`: 6 planes (top and bottom with a circular hole) and the concave cylinder of
///   the through-hole;
/// - `box_with_blind_hole`: 6 planes, the hole's concave cylinder and its flat bottom (8);
/// - `box_with_boss`: 6 box planes, the boss cylinder and the boss cap plane (8);
/// - `box_with_dome`: 6 box planes and a spherical cap rising from the top face (7);
/// - `stepped_block`: an L-shaped extrusion, 8 planes;
/// - `cylinder_with_sphere_cap`: a capsule-like solid: cylinder, hemisphere and bottom disc;
/// - `chamfered_cylinder`: cylinder, its top edge chamfered at 45 degrees (a cone), 2 discs (4);
/// - `filleted_cylinder`: cylinder, its top edge rounded by a tangent fillet (a quarter torus),
///   2 discs (4);
/// - `box_with_countersink`: 6 planes, a through-hole's concave cylinder and the countersink's
///   concave cone (8).
std::vector<std::string> shape_names();

/// Generates the catalogue shape `name`.
/// Throws InvalidInputError for an unknown name or options out of range.
GroundTruthShape make_shape(std::string_view name, const ShapeOptions& options = {});

}  // namespace primseg
