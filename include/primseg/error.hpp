#pragma once
/// @file error.hpp
/// The exceptions primseg throws at its API boundary. Every one derives from primseg::Error, so a
/// caller can catch that alone; the subclasses say which kind of failure it was.

#include <cstdint>
#include <stdexcept>
#include <string>

namespace primseg {

/// Base class of every exception primseg throws on bad input or bad use.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A file could not be opened, read or written (missing file, permission, disk full).
class IoError : public Error {
 public:
  using Error::Error;
};

/// A mesh or tree file is malformed. The message names the file and the line (text formats) or
/// byte offset (binary formats) where reading stopped.
class ParseError : public Error {
 public:
  using Error::Error;
};

/// Data that parsed but cannot be used: NaN coordinates, no faces, indices out of range, a
/// cluster count outside 1..F, an unknown primitive name.
class InvalidInputError : public Error {
 public:
  using Error::Error;
};

}  // namespace primseg
