#pragma once
/// @file render.hpp
/// A small software renderer for pictures of a mesh coloured per input face (segmentations,
/// before/after comparisons), and a PNG writer. No GPU and no image library: the renderer is a
/// z-buffer rasteriser and the PNG encoder writes its own deflate stream.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "primseg/mesh.hpp"

namespace primseg {

/// How render_mesh frames and shades the picture.
///
/// Projection is orthographic: the picture of a mesh does not depend on its scale or position,
/// parallel edges stay parallel (which reads well for CAD parts), and no near plane can cut the
/// model. The camera looks at the centre of a box (by default the bounding box of the vertices
/// used by triangles) and zooms so that the box's outline, as seen from view_direction, fills the
/// picture but for a margin of 5% on each side. Framing thus depends on the box alone, not on the
/// mesh's detail: two meshes rendered with the same frame_box and view line up pixel for pixel.
struct RenderOptions {
  /// Picture size in pixels, each in 1..16384.
  int width = 800;
  int height = 600;
  /// Direction from the eye towards the model; need not be unit length (normalised here). The
  /// default looks down from the front-right-top, a three-quarter view of a model with +Y up.
  std::array<double, 3> view_direction{-1.0, -0.8, -1.3};
  /// Direction that points up in the picture (its component along view_direction is ignored).
  /// When nearly parallel to view_direction, the world axis most perpendicular to the view is used.
  std::array<double, 3> up{0.0, 1.0, 0.0};
  /// Box to frame, as {low corner, high corner}; unset: the mesh's bounding box. Set it to the same
  /// box for pictures that must be comparable (before/after denoising, several segmentations).
  std::optional<std::array<Vec3, 2>> frame_box;
  /// Draws the visible triangle edges as thin dark lines (shows the tessellation).
  bool edges = false;
  /// Draws, as the same lines, only the edges between faces of different colours and the edges of
  /// the mesh's open boundary: the borders of a segmentation (borders.hpp), not its tessellation.
  bool borders = false;
  /// Colour of pixels that no triangle covers.
  std::array<std::uint8_t, 3> background{255, 255, 255};
  /// Shading is flat per triangle: colour * (ambient + (1 - ambient) * |n·v|), where n is the
  /// triangle's unit normal and v the view direction (a headlight). The absolute value makes it
  /// two-sided, so inconsistently oriented faces look the same as the others. In [0, 1].
  double light_ambient = 0.35;
  /// Anti-aliasing: the picture is rasterised with supersample × supersample samples per pixel
  /// and box-filtered down. 1 disables it; in 1..8.
  int supersample = 2;
};

/// Renders the mesh's triangles, each in the colour of its input face, into RGB8 pixels.
///
/// `face_colors` has one colour per input face (shape (F)); empty paints every face light grey.
/// Returns width * height * 3 bytes, row-major, top row first. Output is deterministic: the same
/// input gives the same bytes. Zero-area triangles are skipped; an empty mesh gives a picture of
/// the background. Throws InvalidInputError on options out of range, a face_colors size other
/// than 0 or F, or a mesh whose triangles index out of range.
std::vector<std::uint8_t> render_mesh(const Mesh& mesh,
                                      std::span<const std::array<std::uint8_t, 3>> face_colors,
                                      const RenderOptions& options = {});

/// Where render_mesh(mesh, ..., options) draws each model-space point: pixel coordinates (x to the
/// right, y down, the centre of pixel (i, j) at (i + 0.5, j + 0.5)), shape (n). For drawing
/// overlays (skeletons, markers) on a rendered picture. Same checks as render_mesh.
std::vector<std::array<double, 2>> project_to_picture(const Mesh& mesh,
                                                      std::span<const Vec3> points,
                                                      const RenderOptions& options = {});

/// Encodes RGB8 pixels (width * height * 3 bytes, row-major, top row first) as a PNG file image:
/// 8-bit truecolour, per-row adaptive filters, zlib stream compressed with fixed-Huffman
/// deflate (stored blocks when that would be smaller). Throws InvalidInputError when the sizes do
/// not agree or width/height is not positive.
std::string encode_png(std::span<const std::uint8_t> rgb, int width, int height);

/// encode_png, written to `path` through a temporary file beside it that is renamed into place.
/// Throws IoError when the file cannot be written, InvalidInputError as encode_png.
void write_png(const std::filesystem::path& path, std::span<const std::uint8_t> rgb, int width,
               int height);

/// render_mesh, then write_png of the picture.
void write_png(const std::filesystem::path& path, const Mesh& mesh,
               std::span<const std::array<std::uint8_t, 3>> face_colors,
               const RenderOptions& options = {});

}  // namespace primseg
