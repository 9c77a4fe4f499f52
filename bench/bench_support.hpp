#pragma once
// Shared helpers of the benchmarks: the CGAL sample meshes, the input a command line names and
// the process's memory figures.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "primseg/mesh.hpp"
#include "primseg/primitive.hpp"

namespace primseg::bench {

/// Path of a mesh shipped by Debian's libcgal-demo (for example "fandisk.off").
///
/// Looks in $PRIMSEG_BENCH_DATA first (a directory holding the mesh files, if set), else
/// extracts the file from /usr/share/doc/libcgal-dev/data.tar.gz into
/// <temp dir>/primseg-cgal-data/data/meshes (the cache the tests use) at first use. Extraction
/// goes to a private directory and is renamed into place, so a concurrent reader never sees a
/// partial file. Throws std::runtime_error when the mesh cannot be found or extracted.
std::filesystem::path cgal_mesh(const std::string& name);

/// The whole of `text` as a number, or std::invalid_argument naming the option.
double number_argument(const std::string& option, const char* text);
/// The whole of `text` as a whole number from `low` to `high` (a count of `what`s), or
/// std::invalid_argument naming the option.
unsigned count_argument(const std::string& option, const char* text, unsigned low, unsigned high,
                        const std::string& what);
/// A comma-separated list of primitive type names ("plane,sphere") as HierarchyOptions::primitives,
/// or std::invalid_argument naming the option and the unknown name.
std::vector<PrimitiveType> primitives_argument(const std::string& option, const std::string& text);

/// The mesh a benchmark's command line names: `MESH_FILE`, `--cgal NAME` (cgal_mesh()) or
/// `--shape NAME [EDGE_LENGTH]` (a generated shape in its Uniform tessellation, edges of
/// EDGE_LENGTH times its size, default 0.01).
struct InputArgument {
  enum class Kind { None, File, Cgal, Shape };
  Kind kind = Kind::None;
  std::string name;
  double edge_length = 0.01;

  /// Takes argv[i] (and what follows it) if it names the input and none was named yet, moving i
  /// to its last word; false otherwise. Throws std::invalid_argument for an EDGE_LENGTH that is
  /// not a number.
  bool take(int argc, char** argv, int& i);
  /// The file to read (extracted by cgal_mesh() for --cgal); empty for a shape.
  std::filesystem::path file() const;
  /// Reads file() or generates the shape.
  Mesh load() const;
};

/// A tool's main(): run(argc, argv), or a message "TOOL: what()" on stderr and exit status 1 if
/// it throws.
int main_reporting_errors(const char* tool, int (*run)(int, char**), int argc, char** argv);

/// High-water mark of the resident set size of this process (getrusage ru_maxrss), bytes.
std::size_t peak_rss_bytes();

/// Current resident set size of this process (/proc/self/statm), bytes; 0 if unavailable.
std::size_t current_rss_bytes();

}  // namespace primseg::bench
