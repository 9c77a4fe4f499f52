#pragma once
// Whole-file reads and atomic writes: every file primseg reads or writes goes through here.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
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

/// The memory this process may use, in bytes: the machine's physical memory, or the process's
/// address-space limit (ulimit -v) when lower; 0 if unknown.
std::uint64_t usable_memory_bytes();

/// Bounds on a read whose size is known only at its end (standard input, a pipe, a device).
struct ReadLimits {
  /// Most bytes accepted: one more stops the read with InvalidInputError "<name>: more than
  /// <limit_name> <max_bytes> bytes" (limit_name: the option that set it, if any).
  std::uint64_t max_bytes = UINT64_MAX;
  std::string_view limit_name;
  /// Without max_bytes, data that has no size (a pipe, a device) is read up to this fraction of
  /// usable_memory_bytes(), so that an endless pipe stops there instead of filling the memory.
  /// The default suits meshes: processing one takes about ten times its file's bytes (512 per
  /// triangle against 50 in a binary STL), so no larger one could be processed anyway.
  double unsized_memory_fraction = 1.0 / 8;
  /// Called after each read with the bytes read so far and the most the read accepts (max_bytes,
  /// or the memory bound if lower); throws to stop reading (data that already cannot be what
  /// the caller expects).
  std::function<void(std::span<const char> prefix, std::uint64_t most_bytes)> check_prefix;
};

/// Reads a whole file. Throws IoError (missing, a directory, unreadable, larger than the
/// machine's physical memory), InvalidInputError "'<path>': the file has N bytes, more than
/// <limit>" before reading a file over `limits.max_bytes`, or what `limits` throws.
FileImage read_file(const std::filesystem::path& path, const ReadLimits& limits = {});

/// Reads standard input to its end (a pipe, a terminal or a redirected file). Throws IoError
/// (unreadable, or more bytes than the machine's physical memory), or what `limits` throws.
FileImage read_standard_input(const ReadLimits& limits = {});

/// Writes to an unnamed file in the target's directory (O_TMPFILE; a hidden named one where the
/// filesystem lacks it), then names it and renames it over the target: readers see the old file
/// or the complete new one, never a partial write, and a process killed while writing leaves
/// nothing behind. A symbolic link is followed (the file it names is replaced, the link stays),
/// and an existing file that is not a regular one (a device such as /dev/null, a FIFO) is written
/// as it is, never replaced. Throws IoError (also for a directory).
/// `while_named`, if set, runs once the temporary file has its name and before the rename (for
/// tests of what an interruption there leaves).
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           const std::function<void()>& while_named = {});

/// Creates a directory and its missing parents (std::filesystem::create_directories); throws
/// IoError "cannot create the directory '<path>': <reason>" (a file in the way, no permission).
void create_directories(const std::filesystem::path& path);

/// Writes `bytes` to standard output and flushes it. Throws IoError when the write fails (a full
/// disk, a closed pipe whose SIGPIPE is ignored), so that a truncated output is never silent.
void write_standard_output(std::string_view bytes);

/// For programs (the CLI's main()), not for a library user's process: installs handlers for
/// SIGINT, SIGTERM and SIGHUP that leave their default action (termination) immediate, except
/// while write_file_atomically() is between naming its temporary file and renaming it, in any
/// thread; a signal arriving then terminates the process as soon as no such write is left, so an
/// interrupted run leaves each output whole or absent, never a temporary file. Signals whose
/// action is not the default (ignored, e.g. under nohup) are left alone.
void defer_termination_during_writes();

}  // namespace primseg::detail
