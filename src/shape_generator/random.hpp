#pragma once
/// @file random.hpp
/// A fully specified random source: std::normal_distribution's output is implementation-defined,
/// and shapes must be bit-identical for a given seed.

#include <cmath>
#include <cstdint>
#include <numbers>

namespace primseg::shape_detail {

/// splitmix64 (Steele, Lea, Flood 2014) with uniform and Box-Muller normal variates.
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}

  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Standard normal variate. The second Box-Muller value is dropped: simpler state, and speed
  /// does not matter here.
  double normal() {
    const double u1 = 1.0 - uniform();  // in (0, 1], so the logarithm is finite
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  std::uint64_t state_;
};

}  // namespace primseg::shape_detail
