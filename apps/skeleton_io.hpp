#pragma once
// What `primseg skeleton` and `primseg deform` share: the skeleton file (written by one, read by
// the other), the pose file, the skin weights file and the picture options.

#include <CLI/CLI.hpp>
#include <array>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "primseg/render.hpp"
#include "primseg/skeleton.hpp"
#include "primseg/skinning.hpp"

namespace primseg::cli {

/// The skeleton file: `summary` (the caller's "mesh", "timing"...) with {"joints": [{"id",
/// "position", "kind", "visible", "bones"}], "bones": [{"id", "cluster", "joints", "visible",
/// "axis", "point", "radius", "area"}], "cluster_count", "root_bone", "face_labels"}, input
/// units, as JSON text.
std::string skeleton_file_text(const Skeleton& skeleton, nlohmann::json summary);

/// Reads a skeleton file. Throws ParseError naming the file and what is wrong.
Skeleton read_skeleton_file(const std::string& path);

/// Reads a pose file: {"rotations": [{"joint": J, "axis": [x, y, z], "degrees": A}]}.
/// Throws ParseError naming the file and what is wrong.
std::vector<JointRotation> read_pose_file(const std::string& path);

/// Text, one line per vertex: "bone weight bone weight ..." (bones increasing, weights summing
/// to 1, 17 significant digits); an unused vertex has an empty line.
std::string skin_weights_text(const SkinWeights& weights);

/// --png FILE, --view X,Y,Z and --up X,Y,Z: a picture of the skeleton over the mesh.
struct SkeletonPicture {
  std::optional<std::string> png;
  std::array<double, 3> view = RenderOptions{}.view_direction;
  std::array<double, 3> up = RenderOptions{}.up;

  void add_options(CLI::App& command, const std::string& what);
  /// Writes the picture when --png was given.
  void write(const Mesh& mesh, const Skeleton& skeleton) const;
};

}  // namespace primseg::cli
