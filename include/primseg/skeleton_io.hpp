#pragma once
/// @file skeleton_io.hpp
/// The skeleton file (written by `primseg skeleton -o`, read by `primseg deform`) and the pose
/// file, both JSON, input units.
///
/// Skeleton file: {"cluster_count": K, "root_bone": 0, "face_labels": [F labels],
/// "joints": [{"id", "position": [x, y, z], "kind": "sensitive" | "locked" | "virtual",
/// "visible", "bones": [ids]}], "bones": [{"id", "cluster", "joints": [ids], "visible",
/// "axis": [x, y, z], "point": [x, y, z], "radius", "area"}]}. The CLI adds "mesh",
/// "primitives", "requested_clusters" and "timing"; readers ignore members they do not use.
///
/// Pose file: {"rotations": [{"joint": J, "axis": [x, y, z], "degrees": A}]} (skinning.hpp's
/// JointRotation, the angle in degrees).

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "primseg/skeleton.hpp"
#include "primseg/skinning.hpp"

namespace primseg {

/// The skeleton file's text. Every double is written with the digits that read back exactly.
std::string skeleton_json(const Skeleton& skeleton);

/// Parses a skeleton file's text. Checks the ids (0..K-1 and 0..J-1 in order), that joints and
/// bones list each other, the kinds, finite positions and directions, finite radii and areas >= 0,
/// labels < K and root_bone 0; members it does not use are ignored. Throws ParseError naming `name`
/// and what is wrong. (It cannot check that the labels fit a mesh: compare face_labels.size() with
/// the mesh's face count.)
Skeleton parse_skeleton_json(std::string_view text, const std::string& name = "<memory>");

/// Reads a skeleton file. Throws IoError, ParseError.
Skeleton read_skeleton(const std::filesystem::path& path);
/// Writes skeleton_json() to a file, atomically (under a temporary name, then renamed). Throws
/// IoError.
void write_skeleton(const std::filesystem::path& path, const Skeleton& skeleton);

/// Parses a pose file's text: finite axes and angles, joint ids as integers (whether they exist
/// and may turn is pose_bones()'s to check). Throws ParseError naming `name`.
std::vector<JointRotation> parse_pose_json(std::string_view text,
                                           const std::string& name = "<memory>");

/// Reads a pose file. Throws IoError, ParseError.
std::vector<JointRotation> read_pose(const std::filesystem::path& path);

}  // namespace primseg
