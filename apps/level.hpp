#pragma once
// Which level of the hierarchy a command reports, as given on the command line.

#include <optional>
#include <string>

#include "primseg/auto_level.hpp"
#include "primseg/cut.hpp"

namespace primseg::cli {

struct LevelChoice {
  std::optional<std::string> clusters;   // --clusters K or auto
  std::optional<std::string> tolerance;  // --tolerance T or T% (of the bounding-box diagonal)
};

/// detail::parse_length() of --tolerance ("T" or "T%" of `bounding_box_diagonal`).
double parse_tolerance(const std::string& text, double bounding_box_diagonal);

/// Parses --clusters: a count, or std::nullopt for "auto". Throws InvalidInputError naming the
/// option for anything else (including counts beyond 32 bits).
std::optional<std::uint32_t> parse_cluster_count(const std::string& text);

/// Throws InvalidInputError unless the level can be cut from a mesh of `face_count` faces (K in
/// 1..F or auto, a well-formed tolerance): checked before the hierarchy is built.
void validate_level(const LevelChoice& level, std::uint32_t face_count);

/// A cut level, and how it was chosen when --clusters auto.
struct ChosenLevel {
  Segmentation segmentation;
  std::optional<AutoLevel> automatic;
  // denoise --clusters auto (Denoiser::automatic_level): the noise estimate and the tolerance
  // at a multiple of it, the worst cluster RMS of the curve's jump (0 without one), all in input
  // units, and whether the level is the tolerance cut (no jump, or one beyond
  // kMaxJumpClusterRmsInTolerances).
  struct Noise {
    double estimate = 0, tolerance = 0, jump_worst_rms = 0;
    bool level_by_noise = false;
  };
  std::optional<Noise> noise;
};

/// The segmentation for a level choice; with neither option, the default tolerance below.
ChosenLevel cut(const Hierarchy& hierarchy, const LevelChoice& level);

/// Default level when none is given: clusters whose RMS estimate is within this percentage of
/// the bounding-box diagonal.
inline constexpr const char* kDefaultTolerance = "0.1%";

}  // namespace primseg::cli
