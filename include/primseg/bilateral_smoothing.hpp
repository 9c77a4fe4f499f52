#pragma once
/// @file bilateral_smoothing.hpp
/// Feature-preserving mesh smoothing by bilateral filtering of the face normals followed by a
/// vertex update that fits the faces to the filtered normals (Zheng, Fu, Au, Tai 2011, "Bilateral
/// Normal Filtering for Mesh Denoising"; vertex update of Sun et al. 2007). A face's normal is
/// averaged with those of its neighbours (faces sharing a vertex), weighted by their area, by a
/// Gaussian of the distance between centroids and by a Gaussian of the normal difference: across
/// a sharp edge the normals differ, so the edge survives, while noise on a smooth part is
/// averaged away. Denoising segments such a smoothed copy (DenoiseOptions::smoothing) so that
/// noise does not fragment curved parts into small planes, without rounding the edges as uniform
/// (Taubin) smoothing does.

#include "primseg/mesh.hpp"

namespace primseg {

/// Options of bilateral_smooth(). Defaults suit scans with noise up to about a third of the mean
/// edge length.
struct BilateralSmoothingOptions {
  /// Passes of normal filtering (each pass filters every face normal once, from the previous
  /// pass's normals). >= 0.
  int normal_iterations = 20;
  /// Gaussian width of the normal difference |n_i − n_j| (unit normals, so in [0, 2]): normals
  /// farther apart than about this do not average, which keeps edges sharper than roughly
  /// 2 asin(σ/2), 40 degrees for the default. > 0.
  double normal_sigma = 0.35;
  /// Gaussian width of the centroid distance, as a multiple of the mean distance between the
  /// centroids of faces sharing an edge. > 0.
  double spatial_sigma = 1.0;
  /// Passes of the vertex update (each moves every vertex towards the planes of its faces, with
  /// the filtered normals). >= 0.
  int vertex_iterations = 10;
  /// Threads over the faces and vertices of each pass (0: all hardware threads); the result is
  /// the same, bit for bit, for any number.
  unsigned threads = 0;

  bool operator==(const BilateralSmoothingOptions&) const = default;
};

/// Throws InvalidInputError for options out of range.
void validate(const BilateralSmoothingOptions& options);

/// A copy of `mesh` with the positions smoothed; same vertices, triangles and order. Normals are
/// compared with the triangles consistently oriented, as DualGraph orients them, so the result
/// does not depend on how the file orients its faces (up to round-off). Faces of zero area keep
/// no normal and take no part in the filtering. A vertex on more than 64 triangles (a fan's hub,
/// a book's spine) joins only the faces across each of its edges into a ring, chained at a
/// non-manifold edge as DualGraph chains them, so that ring sizes stay bounded: all the faces
/// around it would cost O(valence²) per pass. Deterministic; O((normal_iterations
/// + vertex_iterations) × Σ ring sizes) with rings of at most about 3 × 64 faces. Throws
/// InvalidInputError for invalid options or a mesh that fails Mesh::validate().
Mesh bilateral_smooth(const Mesh& mesh, const BilateralSmoothingOptions& options = {});

}  // namespace primseg
