#pragma once
// Shared helpers of the benchmarks: the CGAL sample meshes and the process's memory figures.

#include <cstddef>
#include <filesystem>
#include <string>

namespace primseg::bench {

/// Path of a mesh shipped by Debian's libcgal-demo (for example "fandisk.off").
///
/// Looks in $PRIMSEG_BENCH_DATA first (a directory holding the mesh files, if set), else
/// extracts the file from /usr/share/doc/libcgal-dev/data.tar.gz into
/// <temp dir>/primseg-cgal-data/data/meshes (the cache the tests use) at first use. Extraction
/// goes to a private directory and is renamed into place, so a concurrent reader never sees a
/// partial file. Throws std::runtime_error when the mesh cannot be found or extracted.
std::filesystem::path cgal_mesh(const std::string& name);

/// High-water mark of the resident set size of this process (getrusage ru_maxrss), bytes.
std::size_t peak_rss_bytes();

/// Current resident set size of this process (/proc/self/statm), bytes; 0 if unavailable.
std::size_t current_rss_bytes();

}  // namespace primseg::bench
