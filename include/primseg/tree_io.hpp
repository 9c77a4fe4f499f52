#pragma once
/// @file tree_io.hpp
/// The tree file: a whole hierarchy in one self-contained, versioned, little-endian binary file
/// (the mesh, the options, every merge with its cost, primitive, weight and face count, and a
/// checksum), so that any level can be cut and reported later without the mesh file and without
/// recomputing. docs/tree-format.md gives the layout.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "primseg/hierarchy.hpp"

namespace primseg {

/// The tree file's bytes.
std::string serialize_tree(const Hierarchy& hierarchy);
/// Parses a tree file image. Throws ParseError (with the byte offset) for a foreign, truncated,
/// corrupt (checksum) or newer-version file, InvalidInputError for an inconsistent tree.
Hierarchy deserialize_tree(std::span<const char> bytes, const std::string& name = "<memory>");

/// What the first bytes of a tree file tell of its size, for data that arrives in pieces (a
/// pipe), so that a reader can stop as soon as the data cannot be a tree it can hold.
struct TreeSizeBound {
  std::uint64_t bytes = 0;  ///< the fewest bytes the whole file can have
  bool exact = false;       ///< true once every count is known: `bytes` is the file's size
};
/// The size the header and the counts in `prefix` (the first bytes of a tree file) declare.
/// Throws ParseError, as deserialize_tree() would for the whole file, when `prefix` already shows
/// that it is no tree file this primseg reads: a wrong magic number or another version. Counts so
/// large that the size overflows give UINT64_MAX.
TreeSizeBound tree_size_from_prefix(std::span<const char> prefix,
                                    const std::string& name = "<memory>");

/// Writes the tree file atomically. Throws IoError.
void write_tree(const std::filesystem::path& path, const Hierarchy& hierarchy);
/// Reads a tree file. Throws IoError, ParseError, InvalidInputError.
Hierarchy read_tree(const std::filesystem::path& path);

}  // namespace primseg
