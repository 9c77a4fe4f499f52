#include "json_document.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

namespace primseg::detail {

nlohmann::json vec3_json(const Vec3& v) {
  return nlohmann::json::array({v[0], v[1], v[2]});
}

std::string dump_document(const nlohmann::json& document, std::span<const StreamedArray> arrays) {
  // File names need not be UTF-8: replace what JSON cannot hold rather than fail.
  const auto dump = [](const nlohmann::json& json) {
    return json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  };
  const std::string head = dump(document) + "\n";
  // Each array's place in the head, where the document prints it empty at the top level.
  std::vector<std::pair<std::size_t, const StreamedArray*>> places;
  for (const StreamedArray& array : arrays) {
    if (array.size == 0) continue;
    const std::size_t at = head.find("\n  \"" + std::string(array.name) + "\": []");
    if (at == std::string::npos)
      throw std::logic_error("dump_document: no empty top-level array " + std::string(array.name));
    places.emplace_back(at, &array);
  }
  std::sort(places.begin(), places.end());
  std::string text;
  std::size_t copied = 0;
  for (const auto& [at, array] : places) {
    const std::string opening = "\n  \"" + std::string(array->name) + "\": [";
    text.append(head, copied, at - copied).append(opening);
    // Each element as the whole document would print it, two levels in.
    for (std::size_t i = 0; i < array->size; ++i) {
      text += i == 0 ? "\n    " : ",\n    ";
      for (const char c : dump(array->element(i))) {
        text += c;
        if (c == '\n') text += "    ";
      }
    }
    text += "\n  ]";
    copied = at + opening.size() + 1;  // past the empty array's "]"
  }
  text.append(head, copied);
  return text;
}

}  // namespace primseg::detail
