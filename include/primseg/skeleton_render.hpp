#pragma once
/// @file skeleton_render.hpp
/// Pictures of a skeleton drawn over its mesh (render.hpp does the mesh).

#include <cstdint>
#include <filesystem>
#include <vector>

#include "primseg/render.hpp"
#include "primseg/skeleton.hpp"

namespace primseg {

/// Renders the mesh with each cluster in a pale colour, then draws the skeleton on top of it
/// (not hidden by the surface, so that joints inside the body show): visible bones as dark
/// segments (a limb from joint to joint, a hub from the mean of its joints to each of them),
/// hidden bones as thin grey ones, sensitive joints as red discs, virtual joints as blue discs and
/// locked joints as grey squares. RGB8, width * height * 3 bytes, row-major, top row first;
/// deterministic. Throws InvalidInputError as render_mesh, or when the skeleton's face labels do
/// not match the mesh.
std::vector<std::uint8_t> render_skeleton(const Mesh& mesh, const Skeleton& skeleton,
                                          const RenderOptions& options = {});

/// render_skeleton, then write_png. Throws IoError when the file cannot be written.
void write_skeleton_png(const std::filesystem::path& path, const Mesh& mesh,
                        const Skeleton& skeleton, const RenderOptions& options = {});

}  // namespace primseg
