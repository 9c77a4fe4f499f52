#pragma once
/// @file skeleton_file.hpp
/// The skeleton file with the caller's own members (library-private; the CLI adds its summary).

#include <nlohmann/json.hpp>
#include <string>

#include "primseg/skeleton.hpp"

namespace primseg::detail {

/// skeleton_json()'s text with `summary`'s members (an object: "mesh", "timing"...) first; the
/// joints and bones are printed one at a time, never held whole as a document.
std::string skeleton_file_text(const Skeleton& skeleton, nlohmann::json summary);

}  // namespace primseg::detail
