#pragma once
// What `primseg skeleton` and `primseg deform` share besides the skeleton and pose files
// (primseg/skeleton_io.hpp): the skin weights file, the joint rule and the picture options.

#include <CLI/CLI.hpp>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "primseg/render.hpp"
#include "primseg/skeleton.hpp"
#include "primseg/skinning.hpp"

namespace primseg::cli {

/// Text, one line per vertex: "bone weight bone weight ..." (bones increasing, weights summing
/// to 1, 17 significant digits); an unused vertex has an empty line.
std::string skin_weights_text(const SkinWeights& weights);

/// --joints paper|limbs (SkeletonOptions::joints) into `joints`, its help starting with
/// `help_prefix`.
void add_joints_option(CLI::App& command, std::string& joints, const std::string& help_prefix = "");
/// The options --joints names; throws InvalidInputError for an unknown rule.
SkeletonOptions skeleton_options(const std::string& joints);
/// The options --band gives; throws InvalidInputError unless it is finite and >= 0.
SkinningOptions skinning_options(double band);

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
