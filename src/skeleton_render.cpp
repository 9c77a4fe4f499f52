#include "primseg/skeleton_render.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"
#include "skeleton_geometry.hpp"

namespace primseg {
namespace {

using PixelPoint = std::array<double, 2>;
using Rgb = std::array<std::uint8_t, 3>;

constexpr Rgb kBoneColor{25, 25, 25};
constexpr Rgb kHiddenBoneColor{150, 150, 150};
constexpr Rgb kSensitiveColor{215, 30, 30};
constexpr Rgb kVirtualColor{30, 90, 215};
constexpr Rgb kLockedColor{110, 110, 110};

// A picture and the primitives drawn on it (pixel centres at +0.5).
class Canvas {
 public:
  Canvas(std::vector<std::uint8_t>& rgb, int width, int height)
      : rgb_(rgb), width_(width), height_(height) {}

  // Pixels whose centre is within half_width of the segment.
  void segment(PixelPoint a, PixelPoint b, double half_width, const Rgb& color) {
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const double length2 = dx * dx + dy * dy;
    fill_box(std::min(a[0], b[0]) - half_width, std::max(a[0], b[0]) + half_width,
             std::min(a[1], b[1]) - half_width, std::max(a[1], b[1]) + half_width, color,
             [&](double x, double y) {
               double t = length2 > 0 ? ((x - a[0]) * dx + (y - a[1]) * dy) / length2 : 0;
               t = std::clamp(t, 0.0, 1.0);
               const double ex = x - (a[0] + t * dx), ey = y - (a[1] + t * dy);
               return ex * ex + ey * ey <= half_width * half_width;
             });
  }

  void disc(PixelPoint c, double radius, const Rgb& color) {
    fill_box(c[0] - radius, c[0] + radius, c[1] - radius, c[1] + radius, color,
             [&](double x, double y) {
               return (x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]) <= radius * radius;
             });
  }

  void square(PixelPoint c, double half_side, const Rgb& color) {
    fill_box(c[0] - half_side, c[0] + half_side, c[1] - half_side, c[1] + half_side, color,
             [](double, double) { return true; });
  }

 private:
  template <typename Inside>
  void fill_box(double x0, double x1, double y0, double y1, const Rgb& color, Inside inside) {
    // Far-off points (a joint outside a frame_box) are clipped to the picture; a position that
    // overflowed to NaN (coordinates near the double range) is not drawn.
    if (std::isnan(x0) || std::isnan(x1) || std::isnan(y0) || std::isnan(y1)) return;
    const int i0 = static_cast<int>(std::clamp(std::floor(x0), 0.0, double(width_)));
    const int i1 = static_cast<int>(std::clamp(std::ceil(x1), 0.0, double(width_)));
    const int j0 = static_cast<int>(std::clamp(std::floor(y0), 0.0, double(height_)));
    const int j1 = static_cast<int>(std::clamp(std::ceil(y1), 0.0, double(height_)));
    for (int j = j0; j < j1; ++j)
      for (int i = i0; i < i1; ++i)
        if (inside(i + 0.5, j + 0.5)) {
          const std::size_t pixel =
              (static_cast<std::size_t>(j) * static_cast<std::size_t>(width_) +
               static_cast<std::size_t>(i)) *
              3;
          for (int c = 0; c < 3; ++c) rgb_[pixel + static_cast<std::size_t>(c)] = color[c];
        }
  }

  std::vector<std::uint8_t>& rgb_;
  int width_, height_;
};

}  // namespace

std::vector<std::uint8_t> render_skeleton(const Mesh& mesh, const Skeleton& skeleton,
                                          const RenderOptions& options) {
  skeleton_detail::check_face_labels(mesh, skeleton, "render_skeleton");
  const auto palette = distinct_colors(skeleton.bones.size());
  std::vector<Rgb> face_colors(mesh.face_count());
  for (std::size_t f = 0; f < face_colors.size(); ++f) {
    const std::uint32_t label = skeleton.face_labels[f];
    for (int c = 0; c < 3; ++c)  // pale, so that the skeleton stands out
      face_colors[f][c] = static_cast<std::uint8_t>((palette[label][c] + 2 * 255) / 3);
  }
  std::vector<std::uint8_t> rgb = render_mesh(mesh, face_colors, options);

  std::vector<Vec3> joint_positions;
  for (const Joint& joint : skeleton.joints) joint_positions.push_back(joint.position);
  const std::vector<PixelPoint> joints = project_to_picture(mesh, joint_positions, options);
  Canvas canvas(rgb, options.width, options.height);
  const double scale = std::max(1.0, std::min(options.width, options.height) / 600.0);
  for (const bool visible_pass : {false, true})  // visible bones over hidden ones
    for (const Bone& bone : skeleton.bones) {
      if (bone.visible != visible_pass || bone.joints.empty()) continue;
      const double half_width = (bone.visible ? 1.6 : 0.8) * scale;
      const Rgb& color = bone.visible ? kBoneColor : kHiddenBoneColor;
      if (bone.joints.size() == 2) {
        canvas.segment(joints[bone.joints[0]], joints[bone.joints[1]], half_width, color);
        continue;
      }
      PixelPoint hub{0, 0};
      for (const std::uint32_t j : bone.joints) {
        hub[0] += joints[j][0] / static_cast<double>(bone.joints.size());
        hub[1] += joints[j][1] / static_cast<double>(bone.joints.size());
      }
      for (const std::uint32_t j : bone.joints) canvas.segment(hub, joints[j], half_width, color);
    }
  for (const Joint& joint : skeleton.joints) {
    if (!joint.visible) continue;
    const PixelPoint& p = joints[joint.id];
    switch (joint.kind) {
      case JointKind::Sensitive:
        canvas.disc(p, 4.5 * scale, kSensitiveColor);
        break;
      case JointKind::Virtual:
        canvas.disc(p, 4.5 * scale, kVirtualColor);
        break;
      case JointKind::Locked:
        canvas.square(p, 4.5 * scale, kBoneColor);
        canvas.square(p, 3 * scale, kLockedColor);
        break;
    }
  }
  return rgb;
}

void write_skeleton_png(const std::filesystem::path& path, const Mesh& mesh,
                        const Skeleton& skeleton, const RenderOptions& options) {
  write_png(path, render_skeleton(mesh, skeleton, options), options.width, options.height);
}

}  // namespace primseg
