#pragma once
/// @file catalogue.hpp
/// The shapes of the catalogue, each built in its own frame by a PatchBuilder.

#include <string_view>
#include <vector>

#include "patch_builder.hpp"

namespace primseg::shape_detail {

struct CatalogueEntry {
  std::string_view name;
  PatchBuilder (*build)(const ShapeOptions& options);
};

/// Every shape, in the order of shape_names().
const std::vector<CatalogueEntry>& catalogue();

}  // namespace primseg::shape_detail
