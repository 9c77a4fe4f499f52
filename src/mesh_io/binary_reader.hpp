#pragma once
// Private to the mesh readers: fixed-size little/big-endian values in a file image, and error
// reporting by byte offset (binary PLY and STL share it).

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>

#include "text_scanner.hpp"

namespace primseg::mesh_io_detail {

enum class ScalarType : std::uint8_t {
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Float32,
  Float64
};

constexpr std::size_t scalar_size(ScalarType type) {
  switch (type) {
    case ScalarType::Int8:
    case ScalarType::UInt8:
      return 1;
    case ScalarType::Int16:
    case ScalarType::UInt16:
      return 2;
    case ScalarType::Int32:
    case ScalarType::UInt32:
    case ScalarType::Float32:
      return 4;
    case ScalarType::Float64:
      return 8;
  }
  return 0;
}

constexpr bool is_floating(ScalarType type) {
  return type == ScalarType::Float32 || type == ScalarType::Float64;
}

inline std::uint16_t byte_swap(std::uint16_t v) {
  return __builtin_bswap16(v);
}
inline std::uint32_t byte_swap(std::uint32_t v) {
  return __builtin_bswap32(v);
}
inline std::uint64_t byte_swap(std::uint64_t v) {
  return __builtin_bswap64(v);
}

/// Loads the unsigned integer of the same size as T at `p`, byte-swapped if `swap`, as T.
template <typename T, typename Bits>
T load_swapped(const char* p, bool swap) {
  static_assert(sizeof(T) == sizeof(Bits));
  Bits bits;
  std::memcpy(&bits, p, sizeof bits);
  if (swap) bits = byte_swap(bits);
  T value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

/// The value of type `type` stored at `p` (with `swap` when its byte order is not the host's).
inline double load_as_double(const char* p, ScalarType type, bool swap) {
  switch (type) {
    case ScalarType::Int8:
      return static_cast<signed char>(*p);
    case ScalarType::UInt8:
      return static_cast<unsigned char>(*p);
    case ScalarType::Int16:
      return load_swapped<std::int16_t, std::uint16_t>(p, swap);
    case ScalarType::UInt16:
      return load_swapped<std::uint16_t, std::uint16_t>(p, swap);
    case ScalarType::Int32:
      return load_swapped<std::int32_t, std::uint32_t>(p, swap);
    case ScalarType::UInt32:
      return load_swapped<std::uint32_t, std::uint32_t>(p, swap);
    case ScalarType::Float32:
      return load_swapped<float, std::uint32_t>(p, swap);
    case ScalarType::Float64:
      return load_swapped<double, std::uint64_t>(p, swap);
  }
  return 0.0;
}

/// A file image read by byte offset; errors name the file and the offset.
class BinaryReader {
 public:
  BinaryReader(std::span<const char> bytes, std::string_view file_name, bool big_endian)
      : bytes_(bytes),
        file_name_(file_name),
        swap_(big_endian != (std::endian::native == std::endian::big)) {}

  const char* data() const { return bytes_.data(); }
  std::size_t size() const { return bytes_.size(); }
  bool swap() const { return swap_; }
  std::string_view file_name() const { return file_name_; }
  bool has(std::size_t offset, std::size_t length) const {
    return offset <= bytes_.size() && length <= bytes_.size() - offset;
  }
  double load(std::size_t offset, ScalarType type) const {
    return load_as_double(bytes_.data() + offset, type, swap_);
  }

  [[noreturn]] void fail_at(std::size_t offset, std::string_view reason,
                            ErrorKind kind = ErrorKind::Parse) const {
    raise(kind, file_name_, offset_location(offset), reason);
  }

 private:
  std::span<const char> bytes_;
  std::string_view file_name_;
  bool swap_;
};

}  // namespace primseg::mesh_io_detail
