#pragma once
/// @file json_document.hpp
/// Writing large JSON documents (library-private; the CLI uses it too): a document whose big
/// arrays are printed element by element, never held whole.

#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>

#include "primseg/mesh.hpp"

namespace primseg::detail {

/// A member of a JSON document that is a large array: dump_document prints its elements, made
/// one at a time, instead of holding them all as a document (about 4 times their text).
struct StreamedArray {
  std::string_view name;                               ///< a top-level member of the document
  std::size_t size = 0;                                ///< elements
  std::function<nlohmann::json(std::size_t)> element;  ///< element i
};

/// `document` as document.dump(2) prints it (invalid UTF-8 replaced), and a newline, with each of
/// `arrays`, an empty array in `document`, holding its elements.
std::string dump_document(const nlohmann::json& document, std::span<const StreamedArray> arrays);

/// A point or direction as the JSON array [x, y, z].
nlohmann::json vec3_json(const Vec3& v);

}  // namespace primseg::detail
