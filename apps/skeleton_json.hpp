#pragma once
// The skeleton file of `primseg skeleton` (read back by `primseg deform`) and the pose file.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "primseg/skeleton.hpp"
#include "primseg/skinning.hpp"

namespace primseg::cli {

/// {"joints": [{"id", "position", "kind", "visible", "bones"}], "bones": [{"id", "cluster",
/// "joints", "visible", "axis", "point", "radius", "area"}], "cluster_count", "root_bone",
/// "face_labels"}, input units. The caller adds "mesh" and the rest of its summary.
nlohmann::json skeleton_to_json(const Skeleton& skeleton);

/// Reads a skeleton file. Throws ParseError naming the file and what is wrong.
Skeleton read_skeleton_file(const std::string& path);

/// Reads a pose file: {"rotations": [{"joint": J, "axis": [x, y, z], "degrees": A}]}.
/// Throws ParseError naming the file and what is wrong.
std::vector<JointRotation> read_pose_file(const std::string& path);

/// Text, one line per vertex: "bone weight bone weight ..." (bones increasing, weights summing
/// to 1, 17 significant digits); an unused vertex has an empty line.
std::string skin_weights_text(const SkinWeights& weights);

}  // namespace primseg::cli
