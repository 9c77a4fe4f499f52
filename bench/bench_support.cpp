#include "bench_support.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <system_error>

#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/primitives/primitive_fitter.hpp"
#include "primseg/shape_generator.hpp"

namespace primseg::bench {
namespace {

/// `text` quoted for /bin/sh.
std::string shell_quote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) {
    if (c == '\'')
      quoted += "'\\''";
    else
      quoted += c;
  }
  return quoted + "'";
}

}  // namespace

std::filesystem::path cgal_mesh(const std::string& name) {
  namespace fs = std::filesystem;
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);

  if (const char* dir = std::getenv("PRIMSEG_BENCH_DATA"); dir != nullptr && *dir != '\0') {
    const fs::path path = fs::path(dir) / name;
    if (!fs::exists(path))
      throw std::runtime_error(path.string() + " does not exist (PRIMSEG_BENCH_DATA)");
    return path;
  }

  const fs::path archive = "/usr/share/doc/libcgal-dev/data.tar.gz";
  const fs::path cache = fs::temp_directory_path() / "primseg-cgal-data";
  const fs::path path = cache / "data" / "meshes" / name;
  if (fs::exists(path)) return path;
  if (!fs::exists(archive))
    throw std::runtime_error(archive.string() + " is missing: install Debian's libcgal-demo");

  const fs::path staging = cache / ("staging-" + std::to_string(::getpid()));
  fs::remove_all(staging);
  fs::create_directories(staging);
  fs::create_directories(path.parent_path());
  const std::string command = "tar xzf " + shell_quote(archive.string()) + " -C " +
                              shell_quote(staging.string()) + " " +
                              shell_quote("data/meshes/" + name) + " >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  const fs::path extracted = staging / "data" / "meshes" / name;
  std::error_code error;
  if (status == 0 && fs::exists(extracted)) fs::rename(extracted, path, error);
  fs::remove_all(staging, error);
  if (!fs::exists(path))
    throw std::runtime_error("could not extract " + name + " from " + archive.string());
  return path;
}

std::size_t peak_rss_bytes() {
  rusage usage{};
  if (::getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<std::size_t>(usage.ru_maxrss) * 1024;  // Linux: kilobytes
}

std::size_t current_rss_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::size_t pages = 0, resident = 0;
  if (!(statm >> pages >> resident)) return 0;
  return resident * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
}

double number_argument(const std::string& option, const char* text) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0') throw std::invalid_argument(option + ": not a number: " + text);
  return value;
}

unsigned count_argument(const std::string& option, const char* text, unsigned low, unsigned high,
                        const std::string& what) {
  const double value = number_argument(option, text);
  if (!(value >= low && value <= high && value == static_cast<unsigned>(value)))
    throw std::invalid_argument(option + ": not a " + what + " count from " + std::to_string(low) +
                                " to " + std::to_string(high));
  return static_cast<unsigned>(value);
}

std::vector<PrimitiveType> primitives_argument(const std::string& option, const std::string& text) {
  try {
    return fittable_types_from_list(text);
  } catch (const InvalidInputError& error) {
    throw std::invalid_argument(option + ": " + error.what());
  }
}

bool InputArgument::take(int argc, char** argv, int& i) {
  if (kind != Kind::None) return false;
  const std::string arg = argv[i];
  if ((arg == "--cgal" || arg == "--shape") && i + 1 < argc) {
    kind = arg == "--cgal" ? Kind::Cgal : Kind::Shape;
    name = argv[++i];
    if (kind == Kind::Shape && i + 1 < argc && argv[i + 1][0] != '-')
      edge_length = number_argument("EDGE_LENGTH", argv[++i]);
    return true;
  }
  if (arg.starts_with("-")) return false;
  kind = Kind::File;
  name = arg;
  return true;
}

std::filesystem::path InputArgument::file() const {
  if (kind == Kind::File) return name;
  return kind == Kind::Cgal ? cgal_mesh(name) : std::filesystem::path();
}

Mesh InputArgument::load() const {
  if (kind == Kind::None) throw std::invalid_argument("no input named");
  if (kind != Kind::Shape) return read_mesh(file());
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = edge_length;
  return make_shape(name, options).mesh;
}

int main_reporting_errors(const char* tool, int (*run)(int, char**), int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", tool, e.what());
    return 1;
  }
}

}  // namespace primseg::bench
