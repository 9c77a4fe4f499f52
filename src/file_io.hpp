#pragma once
// Whole-file reads and atomic writes: every file primseg reads or writes goes through here.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string_view>

namespace primseg::detail {

/// Throws IoError "cannot <action> '<path>': <strerror(error_number)>".
[[noreturn]] void io_failure(const std::filesystem::path& path, std::string_view action,
                             int error_number);

/// The whole file in one block: readers parse from memory, never through a stream.
struct FileImage {
  std::unique_ptr<char[]> bytes;
  std::size_t size = 0;
  std::string_view view() const { return {bytes.get(), size}; }
};

/// Physical memory of the machine in bytes (0 if unknown).
std::uint64_t physical_memory_bytes();

/// Reads a whole file. Throws IoError (missing, a directory, unreadable, larger than the
/// machine's physical memory).
FileImage read_file(const std::filesystem::path& path);

/// Writes to an unnamed file in the target's directory (O_TMPFILE; a hidden named one where the
/// filesystem lacks it), then names it and renames it over the target: readers see the old file
/// or the complete new one, never a partial write, and a process killed while writing leaves
/// nothing behind. Throws IoError.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace primseg::detail
