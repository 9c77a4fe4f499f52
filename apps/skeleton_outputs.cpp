#include "skeleton_outputs.hpp"

#include <cmath>
#include <cstdio>

#include "primseg/error.hpp"
#include "primseg/skeleton_render.hpp"

namespace primseg::cli {

std::string skin_weights_text(const SkinWeights& weights) {
  std::string text;
  char number[64];
  for (std::uint32_t v = 0; v < weights.vertex_count(); ++v) {
    const auto bones = weights.bones_of(v);
    const auto w = weights.weights_of(v);
    for (std::size_t i = 0; i < bones.size(); ++i) {
      const int n =
          std::snprintf(number, sizeof number, "%s%u %.17g", i ? " " : "", bones[i], w[i]);
      text.append(number, static_cast<std::size_t>(n));
    }
    text += '\n';
  }
  return text;
}

void add_joints_option(CLI::App& command, std::string& joints, const std::string& help_prefix) {
  command
      .add_option("--joints", joints,
                  help_prefix +
                      "Joint rule: paper (touching boundaries merge into locked hubs) or limbs (a "
                      "protruding part also turns where it is attached)")
      ->capture_default_str();
}

SkeletonOptions skeleton_options(const std::string& joints) {
  SkeletonOptions options;
  const std::optional<JointRule> rule = joint_rule_from_string(joints);
  if (!rule) throw InvalidInputError("--joints: '" + joints + "' is not paper or limbs");
  options.joints = *rule;
  return options;
}

SkinningOptions skinning_options(double band) {
  if (!(std::isfinite(band) && band >= 0))
    throw InvalidInputError("--band: must be a finite number >= 0");
  SkinningOptions options;
  options.band = band;
  return options;
}

void SkeletonPicture::add_options(CLI::App& command, const std::string& what) {
  command.add_option("--png", png, "Render " + what + " (800x600 PNG)");
  command.add_option("--view", view, "--png: direction from the eye to the model")
      ->delimiter(',')
      ->capture_default_str();
  command.add_option("--up", up, "--png: direction that points up in the picture")
      ->delimiter(',')
      ->capture_default_str();
}

void SkeletonPicture::write(const Mesh& mesh, const Skeleton& skeleton) const {
  if (!png) return;
  RenderOptions options;
  options.view_direction = view;
  options.up = up;
  write_skeleton_png(*png, mesh, skeleton, options);
}

}  // namespace primseg::cli
