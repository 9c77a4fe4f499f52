#include "file_io.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>

#include "huge_pages.hpp"
#include "primseg/error.hpp"

namespace primseg::detail {

[[noreturn]] void io_failure(const std::filesystem::path& path, std::string_view action,
                             int error_number) {
  throw IoError("cannot " + std::string(action) + " '" + path.string() +
                "': " + std::strerror(error_number));
}

std::uint64_t usable_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page_size = ::sysconf(_SC_PAGESIZE);
  std::uint64_t memory = pages > 0 && page_size > 0 ? static_cast<std::uint64_t>(pages) *
                                                          static_cast<std::uint64_t>(page_size)
                                                    : 0;
  struct rlimit address_space {};
  if (::getrlimit(RLIMIT_AS, &address_space) == 0 && address_space.rlim_cur != RLIM_INFINITY) {
    const auto limit = static_cast<std::uint64_t>(address_space.rlim_cur);
    memory = memory == 0 ? limit : std::min(memory, limit);
  }
  return memory;
}

namespace {

// "--max-memory 1048576 bytes", or "1048576 bytes" for a limit without a name.
std::string limit_phrase(const ReadLimits& limits) {
  return (limits.limit_name.empty() ? "" : std::string(limits.limit_name) + " ") +
         std::to_string(limits.max_bytes) + " bytes";
}

// Reads what is left of `fd` until end of file into a buffer of at least `expected` + 1 bytes
// (the size from fstat may be stale: a growing file, or a pipe, whose size is 0).
// `sized`: the source has a size (a regular file), `expected`; else it is read up to the
// limits' fraction of the usable memory when no max_bytes bounds it.
FileImage read_to_end(int fd, const std::filesystem::path& name, bool sized, std::uint64_t expected,
                      const ReadLimits& limits) {
  const std::uint64_t memory = usable_memory_bytes();
  const std::uint64_t unsized_most =
      !sized && limits.max_bytes == UINT64_MAX && memory != 0
          ? static_cast<std::uint64_t>(static_cast<double>(memory) * limits.unsized_memory_fraction)
          : UINT64_MAX;
  // The buffer never holds more than one byte past a limit: that byte is what tells.
  const std::uint64_t most =
      std::min({limits.max_bytes, memory == 0 ? UINT64_MAX : memory, unsized_most});
  const std::uint64_t largest_buffer = most == UINT64_MAX ? most : most + 1;
  std::size_t capacity = static_cast<std::size_t>(std::min(expected + 1, largest_buffer));
  FileImage image{std::make_unique_for_overwrite<char[]>(capacity), 0};
  advise_huge_pages(image.bytes.get(), capacity);
  // A file's size is known to be there: its pages at once rather than one fault at a time as
  // read() copies into them.
  if (sized) populate_pages(image.bytes.get(), capacity);
  while (true) {
    if (image.size > limits.max_bytes)
      throw InvalidInputError(name.string() + ": more than " + limit_phrase(limits));
    if (image.size > unsized_most)
      throw InvalidInputError(name.string() + ": more than " + std::to_string(unsized_most) +
                              " bytes, the most read without a size (1/" +
                              std::to_string(std::lround(1 / limits.unsized_memory_fraction)) +
                              " of the " + std::to_string(memory) +
                              " bytes of memory this process may use; a command's "
                              "--max-memory sets another limit)");
    if (image.size > most)
      throw IoError("cannot read '" + name.string() + "': more than the memory this process " +
                    "may use (" + std::to_string(memory) + " bytes)");
    if (image.size == capacity) {
      const std::size_t grown = static_cast<std::size_t>(
          std::min<std::uint64_t>(capacity + capacity / 2 + 4096, largest_buffer));
      auto larger = std::make_unique_for_overwrite<char[]>(grown);
      advise_huge_pages(larger.get(), grown);
      std::memcpy(larger.get(), image.bytes.get(), image.size);
      image.bytes = std::move(larger);
      capacity = grown;
    }
    const ssize_t got = ::read(fd, image.bytes.get() + image.size, capacity - image.size);
    if (got < 0) {
      if (errno == EINTR) continue;
      io_failure(name, "read", errno);
    }
    if (got == 0) return image;
    image.size += static_cast<std::size_t>(got);
    if (limits.check_prefix) limits.check_prefix({image.bytes.get(), image.size}, most);
  }
}

}  // namespace

FileImage read_file(const std::filesystem::path& path, const ReadLimits& limits) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) io_failure(path, "open", errno);
  struct FdCloser {
    int fd;
    ~FdCloser() { ::close(fd); }
  } closer{fd};

  struct stat status {};
  if (::fstat(fd, &status) != 0) io_failure(path, "stat", errno);
  if (S_ISDIR(status.st_mode)) io_failure(path, "read", EISDIR);

  // Refused before any allocation: a file over the limit, or larger than the memory this process
  // may use (it could not be parsed). A pipe or a device has no size here: read_to_end() bounds
  // it.
  const auto size = static_cast<std::uint64_t>(status.st_size);
  if (size > limits.max_bytes)
    throw InvalidInputError("'" + path.string() + "': the file has " + std::to_string(size) +
                            " bytes, more than " + limit_phrase(limits));
  const std::uint64_t memory = usable_memory_bytes();
  if (memory != 0 && size > memory)
    throw IoError(
        "cannot read '" + path.string() + "': the file has " + std::to_string(status.st_size) +
        " bytes, more than the memory this process may use (" + std::to_string(memory) + " bytes)");
  return read_to_end(fd, path, S_ISREG(status.st_mode), size, limits);
}

FileImage read_standard_input(const ReadLimits& limits) {
  struct stat status {};
  if (::fstat(STDIN_FILENO, &status) != 0) io_failure("standard input", "stat", errno);
  if (S_ISDIR(status.st_mode)) io_failure("standard input", "read", EISDIR);
  // A pipe has no size: start with a block, the buffer grows by half as it fills.
  const bool sized = S_ISREG(status.st_mode);
  return read_to_end(STDIN_FILENO, "standard input", sized,
                     sized ? static_cast<std::uint64_t>(status.st_size) : std::uint64_t{65536},
                     limits);
}

namespace {

// Writes between naming a temporary file and renaming it (all threads), and a termination signal
// that arrived meanwhile: see defer_termination_during_writes().
std::atomic<int> writes_naming_files{0};
volatile std::sig_atomic_t deferred_signal = 0;
static_assert(std::atomic<int>::is_always_lock_free, "used from a signal handler");

[[noreturn]] void terminate_by(int signal_number) {
  std::signal(signal_number, SIG_DFL);
  // Inside its own handler the signal is blocked: unblock it so that raising it terminates now.
  sigset_t only;
  sigemptyset(&only);
  sigaddset(&only, signal_number);
  ::pthread_sigmask(SIG_UNBLOCK, &only, nullptr);
  std::raise(signal_number);
  std::_Exit(128 + signal_number);  // not reached: the default action terminates
}

extern "C" void defer_or_terminate(int signal_number) {
  deferred_signal = signal_number;
  if (writes_naming_files.load() == 0) terminate_by(signal_number);
}

// Marks a write that has (or will have) a named temporary file until it is renamed or removed.
class NamedTemporaryScope {
 public:
  NamedTemporaryScope() { ++writes_naming_files; }
  ~NamedTemporaryScope() {
    // A signal arriving after the decrement sees no write and terminates by itself; one arriving
    // before it was deferred and is raised here by the last write to finish.
    if (--writes_naming_files == 0 && deferred_signal != 0) terminate_by(deferred_signal);
  }
  NamedTemporaryScope(const NamedTemporaryScope&) = delete;
  NamedTemporaryScope& operator=(const NamedTemporaryScope&) = delete;
};

/// Writes all bytes to fd; false with errno set on failure.
bool write_all(int fd, std::string_view bytes) {
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t result = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (result < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    written += static_cast<std::size_t>(result);
  }
  return true;
}

/// write_all(), then flushes the bytes to disk.
bool write_all_to_disk(int fd, std::string_view bytes) {
  return write_all(fd, bytes) && ::fsync(fd) == 0;
}

// Writes into an existing file that is not a regular one (a device such as /dev/null, a FIFO), as
// it is: putting a regular file in its place would replace the device.
void write_in_place(const std::filesystem::path& path, std::string_view bytes,
                    const std::filesystem::path& name) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) io_failure(name, "open", errno);
  const bool written = write_all(fd, bytes);
  const int error_number = errno;
  if (!written) {
    ::close(fd);
    io_failure(name, "write", error_number);
  }
  if (::close(fd) != 0) io_failure(name, "write", errno);
}

std::filesystem::path temporary_name_for(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path temporary = path;
  // Appended piecewise: `"." + string` trips a false -Wrestrict in g++ 12 release builds.
  std::string name(1, '.');
  name.append(path.filename().string())
      .append(".tmp")
      .append(std::to_string(::getpid()))
      .append("_")
      .append(std::to_string(counter++));
  temporary.replace_filename(name);
  return temporary;
}

}  // namespace

void create_directories(const std::filesystem::path& path) {
  std::error_code error;
  std::filesystem::create_directories(path, error);
  if (error)
    throw IoError("cannot create the directory '" + path.string() + "': " + error.message());
}

void write_standard_output(std::string_view bytes) {
  errno = 0;
  const bool written = std::fwrite(bytes.data(), 1, bytes.size(), stdout) == bytes.size();
  if (!written || std::fflush(stdout) != 0) {
    const int error_number = errno != 0 ? errno : EIO;
    throw IoError("cannot write to standard output: " + std::string(std::strerror(error_number)));
  }
}

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           const std::function<void()>& while_named) {
  // A symbolic link keeps pointing where it did: the file it names is replaced, not the link.
  std::error_code unresolved;
  const std::filesystem::path resolved = std::filesystem::canonical(path, unresolved);
  const std::filesystem::path& target = unresolved ? path : resolved;
  struct stat status {};
  if (::stat(target.c_str(), &status) == 0) {
    if (S_ISDIR(status.st_mode)) io_failure(path, "write", EISDIR);
    if (!S_ISREG(status.st_mode)) {
      write_in_place(target, bytes, path);
      return;
    }
  }
  std::filesystem::path directory = target.parent_path();
  if (directory.empty()) directory = ".";
  // An unnamed file (O_TMPFILE) vanishes by itself if the process is killed while writing: only
  // the final link-and-rename, microseconds long, ever gives it a name. Filesystems without
  // O_TMPFILE get a named temporary file from the start.
  const int fd = ::open(directory.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
  const std::filesystem::path temporary = temporary_name_for(target);
  std::optional<NamedTemporaryScope> named_temporary;
  if (fd >= 0) {
    if (!write_all_to_disk(fd, bytes)) {
      const int error_number = errno;
      ::close(fd);
      io_failure(path, "write", error_number);
    }
    const std::string self = "/proc/self/fd/" + std::to_string(fd);
    named_temporary.emplace();
    if (::linkat(AT_FDCWD, self.c_str(), AT_FDCWD, temporary.c_str(), AT_SYMLINK_FOLLOW) != 0) {
      const int error_number = errno;
      ::close(fd);
      io_failure(path, "name a temporary file for", error_number);
    }
    ::close(fd);
  } else {
    named_temporary.emplace();
    const int named = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (named < 0) io_failure(path, "create a temporary file for", errno);
    const bool written = write_all_to_disk(named, bytes);
    const int error_number = errno;
    if (::close(named) != 0 || !written) {
      ::unlink(temporary.c_str());
      io_failure(path, "write", written ? errno : error_number);
    }
  }
  if (while_named) while_named();
  if (::rename(temporary.c_str(), target.c_str()) != 0) {
    const int error_number = errno;
    ::unlink(temporary.c_str());
    io_failure(path, "rename a temporary file onto", error_number);
  }
}

void defer_termination_during_writes() {
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction current {};
    if (::sigaction(signal_number, nullptr, &current) != 0 || current.sa_handler != SIG_DFL)
      continue;
    struct sigaction action {};
    action.sa_handler = defer_or_terminate;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    ::sigaction(signal_number, &action, nullptr);
  }
}

}  // namespace primseg::detail
