#pragma once
// Writing output files so that a reader never sees a partial one.

#include <filesystem>
#include <string_view>

namespace primseg::detail {

/// Writes `bytes` to a temporary file beside `path`, then renames it into place. Throws IoError.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace primseg::detail
