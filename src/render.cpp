#include "primseg/render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>
#include <utility>

#include "edge_sides.hpp"
#include "file_io.hpp"
#include "primseg/error.hpp"
#include "shape_generator/vector_math.hpp"

namespace primseg {
namespace {

// ---------------------------------------------------------------------------------------------
// Rasteriser
// ---------------------------------------------------------------------------------------------

// Vertices are snapped to 1/256 of a sample so that coverage is decided with exact integer edge
// functions: a sample on an edge shared by two triangles then belongs to exactly one of them (top-
// left rule), which floating point cannot guarantee — it leaves pinholes or double hits.
constexpr int kSubpixelBits = 8;
constexpr std::int64_t kSubpixel = std::int64_t{1} << kSubpixelBits;
constexpr std::int64_t kHalfSubpixel = kSubpixel / 2;

constexpr std::uint32_t kNoTriangle = 0xffffffffu;
// Samples record the triangle that owns them; the top bit marks samples on a drawn edge.
constexpr std::uint32_t kEdgeFlag = 0x80000000u;
constexpr std::uint32_t kTriangleMask = ~kEdgeFlag;

constexpr int kMaxImageSide = 16384;
constexpr int kMaxSupersample = 8;
// The box's outline fills the picture but for 5% of it on each side.
constexpr double kFramingMargin = 1.0 / 0.9;
constexpr std::array<std::uint8_t, 3> kDefaultFaceColor{200, 200, 200};
// Edge lines are the face's shaded colour darkened, so they stay visible on dark faces too while
// keeping the segment's hue.
constexpr double kEdgeDarkening = 0.3;
// Half the width of an edge line, in output pixels: each of the two triangles sharing an edge
// darkens its own side, so interior lines come out one pixel wide.
constexpr double kEdgeHalfWidthPixels = 0.5;

// The shape generator's (a unity build may put both files in one translation unit).
using shape_detail::cross;
using shape_detail::dot;
Vec3 subtract(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Vec3 scaled(const Vec3& a, double s) {
  return {a[0] * s, a[1] * s, a[2] * s};
}
double length(const Vec3& a) {
  return std::sqrt(dot(a, a));
}

// Orthonormal camera frame and the map from model space to sample coordinates (x right, y down).
struct Camera {
  Vec3 centre{};
  Vec3 right{};
  Vec3 up{};
  Vec3 forward{};
  double samples_per_unit = 1.0;
  double inverse_radius = 1.0;  // depth is stored relative to the model size, to suit float
  double half_width = 0.0;      // in samples
  double half_height = 0.0;
};

void validate_options(const RenderOptions& options) {
  auto fail = [](const std::string& what) { throw InvalidInputError("render_mesh: " + what); };
  if (options.width < 1 || options.width > kMaxImageSide || options.height < 1 ||
      options.height > kMaxImageSide) {
    fail("width and height must be in 1.." + std::to_string(kMaxImageSide));
  }
  if (options.supersample < 1 || options.supersample > kMaxSupersample) {
    fail("supersample must be in 1.." + std::to_string(kMaxSupersample));
  }
  if (!(options.light_ambient >= 0.0 && options.light_ambient <= 1.0)) {
    fail("light_ambient must be in [0, 1]");
  }
  const double view_length = length(options.view_direction);
  if (!std::isfinite(view_length) || view_length == 0.0) {
    fail("view_direction must be finite and non-zero");
  }
  if (!std::isfinite(length(options.up))) fail("up must be finite");
  if (options.frame_box) {
    const auto& [low, high] = *options.frame_box;
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(low[axis]) || !std::isfinite(high[axis]) || low[axis] > high[axis]) {
        fail("frame_box must be finite with low <= high");
      }
    }
  }
}

// Also checks the indices, so that the rasteriser and the colour lookup can trust them.
// Returns false when there is no triangle to draw.
bool bounding_box_of_triangles(const Mesh& mesh, Vec3& low, Vec3& high) {
  if (mesh.triangles.size() >= kEdgeFlag) {
    throw InvalidInputError("render_mesh: too many triangles");
  }
  if (mesh.face_of_triangle.size() != mesh.triangles.size()) {
    throw InvalidInputError("render_mesh: face_of_triangle does not match triangles");
  }
  const std::size_t vertex_count = mesh.positions.size();
  const std::uint32_t face_count = mesh.face_count();
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  low = {kInfinity, kInfinity, kInfinity};
  high = {-kInfinity, -kInfinity, -kInfinity};
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (mesh.face_of_triangle[t] >= face_count) {
      throw InvalidInputError("render_mesh: face_of_triangle out of range");
    }
    for (const std::uint32_t v : mesh.triangles[t]) {
      if (v >= vertex_count) throw InvalidInputError("render_mesh: vertex index out of range");
      const Vec3& p = mesh.positions[v];
      for (int axis = 0; axis < 3; ++axis) {
        low[axis] = std::min(low[axis], p[axis]);
        high[axis] = std::max(high[axis], p[axis]);
      }
    }
  }
  return !mesh.triangles.empty();
}

Camera make_camera(const Vec3& low, const Vec3& high, const RenderOptions& options,
                   int sample_width, int sample_height) {
  Camera camera;
  camera.centre = scaled(Vec3{low[0] + high[0], low[1] + high[1], low[2] + high[2]}, 0.5);
  const Vec3 half_size = scaled(subtract(high, low), 0.5);
  double radius = length(half_size);
  // A single point (or coordinates so large the diagonal overflows): any finite frame will do.
  if (!(radius > 0.0) || !std::isfinite(radius)) radius = 1.0;

  camera.forward = scaled(options.view_direction, 1.0 / length(options.view_direction));
  Vec3 right = cross(camera.forward, options.up);
  if (!(length(right) > 1e-6 * length(options.up))) {
    // Fall back to the world axis least aligned with the view.
    int axis = 0;
    for (int candidate = 1; candidate < 3; ++candidate) {
      if (std::abs(camera.forward[candidate]) < std::abs(camera.forward[axis])) axis = candidate;
    }
    Vec3 fallback_up{0.0, 0.0, 0.0};
    fallback_up[axis] = 1.0;
    right = cross(camera.forward, fallback_up);
  }
  camera.right = scaled(right, 1.0 / length(right));
  camera.up = cross(camera.right, camera.forward);

  // The box is symmetric about its centre, so is its outline: the half extents of the outline
  // along right and up are the sums of the half sizes' absolute projections.
  double half_extent_x = 0.0;
  double half_extent_y = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    half_extent_x += half_size[axis] * std::abs(camera.right[axis]);
    half_extent_y += half_size[axis] * std::abs(camera.up[axis]);
  }
  double scale = std::numeric_limits<double>::infinity();
  if (half_extent_x > 0.0) scale = sample_width / (2.0 * half_extent_x * kFramingMargin);
  if (half_extent_y > 0.0) {
    scale = std::min(scale, sample_height / (2.0 * half_extent_y * kFramingMargin));
  }
  // A box seen as a point (a single vertex, or a segment along the view).
  if (!std::isfinite(scale)) scale = std::min(sample_width, sample_height) / (2.0 * radius);

  camera.samples_per_unit = scale;
  camera.inverse_radius = 1.0 / radius;
  camera.half_width = 0.5 * sample_width;
  camera.half_height = 0.5 * sample_height;
  return camera;
}

struct ProjectedVertex {
  std::int64_t x;  // sample coordinates in 1/kSubpixel units
  std::int64_t y;
  float depth;  // larger is farther from the eye
};

std::vector<ProjectedVertex> project_vertices(const Mesh& mesh, const Camera& camera) {
  // Keeps the fixed-point edge functions within 64 bits (coordinates below 2^29 subpixels give
  // products below 2^61). Only vertices far outside a picture of at most 2^17 samples are
  // clamped: unused ones, or ones cut off by a frame_box much smaller than the mesh, whose
  // triangles may then be drawn slightly off at the picture's border.
  constexpr double kCoordinateLimit = double(std::int64_t{1} << 21);
  std::vector<ProjectedVertex> projected(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3 offset = subtract(mesh.positions[v], camera.centre);
    const double x = camera.half_width + dot(offset, camera.right) * camera.samples_per_unit;
    const double y = camera.half_height - dot(offset, camera.up) * camera.samples_per_unit;
    projected[v].x = std::llround(std::clamp(x, -kCoordinateLimit, kCoordinateLimit) * kSubpixel);
    projected[v].y = std::llround(std::clamp(y, -kCoordinateLimit, kCoordinateLimit) * kSubpixel);
    projected[v].depth = static_cast<float>(dot(offset, camera.forward) * camera.inverse_radius);
  }
  return projected;
}

// Edge function of the directed edge from p to q: positive on the triangle's inside once the
// triangle is oriented with positive area, zero on the edge.
struct EdgeFunction {
  std::int64_t step_x;  // change per sample to the right
  std::int64_t step_y;  // change per sample down
  std::int64_t dx;
  std::int64_t dy;
  std::int64_t origin_x;
  std::int64_t origin_y;
  // 0 on top and left edges, -1 on the others: a sample exactly on an edge is inside only for
  // top-left edges, so edges shared by two triangles are filled once.
  std::int64_t bias;

  EdgeFunction(const ProjectedVertex& p, const ProjectedVertex& q)
      : step_x(-(q.y - p.y) * kSubpixel),
        step_y((q.x - p.x) * kSubpixel),
        dx(q.x - p.x),
        dy(q.y - p.y),
        origin_x(p.x),
        origin_y(p.y) {
    // The inside lies in the direction of the gradient (-dy, dx): a left edge has the inside to
    // its right (-dy > 0), a top edge is horizontal with the inside below it (dx > 0).
    const bool top_left = dy < 0 || (dy == 0 && dx > 0);
    bias = top_left ? 0 : -1;
  }
  std::int64_t at(std::int64_t x, std::int64_t y) const {
    return dx * (y - origin_y) - dy * (x - origin_x);
  }
  // Edge distance in subpixel units below which a sample is drawn as an edge line, scaled by the
  // edge length so it compares directly with the edge function.
  double line_threshold(double half_width_subpixels) const {
    return half_width_subpixels * std::sqrt(static_cast<double>(dx) * static_cast<double>(dx) +
                                            static_cast<double>(dy) * static_cast<double>(dy));
  }
};

// First sample index whose centre (index * kSubpixel + kHalfSubpixel) is >= coordinate.
std::int64_t first_sample_at_or_after(std::int64_t coordinate) {
  const std::int64_t shifted = coordinate - kHalfSubpixel;
  // Ceiling division that is also right for negative values.
  return shifted >= 0 ? (shifted + kSubpixel - 1) / kSubpixel : -((-shifted) / kSubpixel);
}
// Last sample index whose centre is <= coordinate.
std::int64_t last_sample_at_or_before(std::int64_t coordinate) {
  const std::int64_t shifted = coordinate - kHalfSubpixel;
  return shifted >= 0 ? shifted / kSubpixel : -((-shifted + kSubpixel - 1) / kSubpixel);
}

struct SampleBuffer {
  int width;
  int height;
  std::vector<float> depth;
  std::vector<std::uint32_t> owner;  // triangle index (| kEdgeFlag), or kNoTriangle

  SampleBuffer(int w, int h)
      : width(w),
        height(h),
        depth(static_cast<std::size_t>(w) * static_cast<std::size_t>(h),
              std::numeric_limits<float>::infinity()),
        owner(depth.size(), kNoTriangle) {}
};

// Lines drawn along a triangle's edges: bit k for its edge from corner k to corner k + 1 (mod 3).
using EdgeMask = std::uint8_t;
constexpr EdgeMask kAllEdges = 7;

void rasterise_triangle(std::uint32_t triangle_index, ProjectedVertex a, ProjectedVertex b,
                        ProjectedVertex c, EdgeMask lines, double edge_half_width_subpixels,
                        SampleBuffer& buffer) {
  std::int64_t twice_area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (twice_area == 0) return;  // degenerate, or seen edge-on
  // The edges opposite a (b to c), b (c to a) and c (a to b).
  bool line_opposite_a = lines & 2, line_opposite_b = lines & 4, line_opposite_c = lines & 1;
  if (twice_area < 0) {  // back-facing in the picture: draw both sides alike
    std::swap(b, c);
    std::swap(line_opposite_b, line_opposite_c);
    twice_area = -twice_area;
  }

  const std::int64_t x_begin =
      std::max<std::int64_t>(0, first_sample_at_or_after(std::min({a.x, b.x, c.x})));
  const std::int64_t x_end =
      std::min<std::int64_t>(buffer.width - 1, last_sample_at_or_before(std::max({a.x, b.x, c.x})));
  const std::int64_t y_begin =
      std::max<std::int64_t>(0, first_sample_at_or_after(std::min({a.y, b.y, c.y})));
  const std::int64_t y_end = std::min<std::int64_t>(
      buffer.height - 1, last_sample_at_or_before(std::max({a.y, b.y, c.y})));
  if (x_begin > x_end || y_begin > y_end) return;

  // weight_of_a is the edge function of the edge opposite a, and so on: barycentric coordinates
  // times twice_area.
  const EdgeFunction opposite_a(b, c);
  const EdgeFunction opposite_b(c, a);
  const EdgeFunction opposite_c(a, b);
  const double depth_gradient_b = (double{b.depth} - double{a.depth}) / double(twice_area);
  const double depth_gradient_c = (double{c.depth} - double{a.depth}) / double(twice_area);

  const bool draw_edges = edge_half_width_subpixels > 0.0 && lines != 0;
  const auto threshold = [&](const EdgeFunction& edge, bool drawn) {
    return draw_edges && drawn ? edge.line_threshold(edge_half_width_subpixels) : 0.0;
  };
  const double line_a = threshold(opposite_a, line_opposite_a);
  const double line_b = threshold(opposite_b, line_opposite_b);
  const double line_c = threshold(opposite_c, line_opposite_c);

  const std::int64_t first_x = x_begin * kSubpixel + kHalfSubpixel;
  for (std::int64_t y = y_begin; y <= y_end; ++y) {
    const std::int64_t sample_y = y * kSubpixel + kHalfSubpixel;
    std::int64_t weight_a = opposite_a.at(first_x, sample_y) + opposite_a.bias;
    std::int64_t weight_b = opposite_b.at(first_x, sample_y) + opposite_b.bias;
    std::int64_t weight_c = opposite_c.at(first_x, sample_y) + opposite_c.bias;
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(buffer.width);
    for (std::int64_t x = x_begin; x <= x_end; ++x) {
      if ((weight_a | weight_b | weight_c) >= 0) {
        const float depth =
            static_cast<float>(double{a.depth} + double(weight_b) * depth_gradient_b +
                               double(weight_c) * depth_gradient_c);
        const std::size_t index = row + static_cast<std::size_t>(x);
        if (depth < buffer.depth[index]) {
          buffer.depth[index] = depth;
          std::uint32_t owner = triangle_index;
          if (draw_edges && (double(weight_a) < line_a || double(weight_b) < line_b ||
                             double(weight_c) < line_c)) {
            owner |= kEdgeFlag;
          }
          buffer.owner[index] = owner;
        }
      }
      weight_a += opposite_a.step_x;
      weight_b += opposite_b.step_x;
      weight_c += opposite_c.step_x;
    }
  }
}

// For each triangle, its edges that are borders: on the mesh's open boundary (one triangle), or
// between faces of different colours. (No colours: the open boundary alone.)
std::vector<EdgeMask> border_line_masks(const Mesh& mesh,
                                        std::span<const std::array<std::uint8_t, 3>> face_colors) {
  std::vector<std::uint32_t> colour_of_triangle(mesh.triangles.size(), 0);
  if (!face_colors.empty())
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& rgb = face_colors[mesh.face_of_triangle[t]];
      colour_of_triangle[t] = rgb[0] | (std::uint32_t{rgb[1]} << 8) | (std::uint32_t{rgb[2]} << 16);
    }
  const std::vector<detail::EdgeSide> sides = detail::edge_sides(mesh, colour_of_triangle);
  std::vector<EdgeMask> lines(mesh.triangles.size(), 0);
  for (std::size_t begin = 0; begin < sides.size();) {
    const std::size_t end = detail::edge_end(sides, begin);
    // Sides are sorted by colour: the colours differ when the first and last do.
    if (end - begin == 1 || sides[begin].label != sides[end - 1].label)
      for (std::size_t i = begin; i < end; ++i) {
        const Triangle& triangle = mesh.triangles[sides[i].triangle];
        for (int k = 0; k < 3; ++k)
          if (std::minmax(triangle[k], triangle[(k + 1) % 3]) ==
              std::minmax(sides[i].low, sides[i].high))
            lines[sides[i].triangle] |= static_cast<EdgeMask>(1 << k);
      }
    begin = end;
  }
  return lines;
}

std::uint8_t to_channel(double value) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(value, 0.0, 255.0)));
}

// Box-filters the samples down to pixels, shading each owning triangle.
std::vector<std::uint8_t> resolve(const SampleBuffer& buffer, const Mesh& mesh,
                                  std::span<const std::array<std::uint8_t, 3>> face_colors,
                                  const Camera& camera, const RenderOptions& options) {
  const int factor = options.supersample;
  const auto pixel_count =
      static_cast<std::size_t>(options.width) * static_cast<std::size_t>(options.height);
  std::vector<std::uint8_t> rgb(pixel_count * 3);

  // Neighbouring samples mostly share a triangle: remember the last one shaded.
  std::uint32_t cached_owner = kNoTriangle;
  std::array<int, 3> cached_color{options.background[0], options.background[1],
                                  options.background[2]};
  auto sample_color = [&](std::uint32_t owner) -> const std::array<int, 3>& {
    if (owner == cached_owner) return cached_color;
    cached_owner = owner;
    if (owner == kNoTriangle) {
      cached_color = {options.background[0], options.background[1], options.background[2]};
      return cached_color;
    }
    const std::uint32_t triangle_index = owner & kTriangleMask;
    const Triangle& triangle = mesh.triangles[triangle_index];
    const Vec3& p0 = mesh.positions[triangle[0]];
    const Vec3 normal =
        cross(subtract(mesh.positions[triangle[1]], p0), subtract(mesh.positions[triangle[2]], p0));
    const double normal_length = length(normal);
    const double facing =
        normal_length > 0.0 ? std::abs(dot(normal, camera.forward)) / normal_length : 0.0;
    double intensity = options.light_ambient + (1.0 - options.light_ambient) * facing;
    if (owner & kEdgeFlag) intensity *= kEdgeDarkening;
    const std::array<std::uint8_t, 3>& base =
        face_colors.empty() ? kDefaultFaceColor
                            : face_colors[mesh.face_of_triangle[triangle_index]];
    for (int channel = 0; channel < 3; ++channel) {
      cached_color[channel] = to_channel(base[channel] * intensity);
    }
    return cached_color;
  };

  const int samples_per_pixel = factor * factor;
  for (int y = 0; y < options.height; ++y) {
    for (int x = 0; x < options.width; ++x) {
      std::array<int, 3> sum{0, 0, 0};
      for (int sy = 0; sy < factor; ++sy) {
        const std::size_t row =
            static_cast<std::size_t>(y * factor + sy) * static_cast<std::size_t>(buffer.width);
        for (int sx = 0; sx < factor; ++sx) {
          const std::array<int, 3>& color =
              sample_color(buffer.owner[row + static_cast<std::size_t>(x * factor + sx)]);
          sum[0] += color[0];
          sum[1] += color[1];
          sum[2] += color[2];
        }
      }
      const std::size_t pixel =
          (static_cast<std::size_t>(y) * static_cast<std::size_t>(options.width) +
           static_cast<std::size_t>(x)) *
          3;
      for (int channel = 0; channel < 3; ++channel) {
        rgb[pixel + static_cast<std::size_t>(channel)] =
            static_cast<std::uint8_t>((sum[channel] + samples_per_pixel / 2) / samples_per_pixel);
      }
    }
  }
  return rgb;
}

// ---------------------------------------------------------------------------------------------
// PNG encoder
// ---------------------------------------------------------------------------------------------

const std::array<std::uint32_t, 256>& crc32_table() {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> result{};
    for (std::uint32_t n = 0; n < 256; ++n) {
      std::uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
      result[n] = c;
    }
    return result;
  }();
  return table;
}

std::uint32_t crc32(std::string_view bytes) {
  const auto& table = crc32_table();
  std::uint32_t c = 0xffffffffu;
  for (const char byte : bytes) {
    c = table[(c ^ static_cast<std::uint8_t>(byte)) & 0xffu] ^ (c >> 8);
  }
  return c ^ 0xffffffffu;
}

std::uint32_t adler32(std::span<const std::uint8_t> bytes) {
  constexpr std::uint32_t kModulus = 65521;
  // 5552 is the largest run whose sums cannot overflow 32 bits before reduction.
  constexpr std::size_t kRun = 5552;
  std::uint32_t a = 1;
  std::uint32_t b = 0;
  for (std::size_t start = 0; start < bytes.size(); start += kRun) {
    const std::size_t end = std::min(bytes.size(), start + kRun);
    for (std::size_t i = start; i < end; ++i) {
      a += bytes[i];
      b += a;
    }
    a %= kModulus;
    b %= kModulus;
  }
  return (b << 16) | a;
}

void append_big_endian(std::string& out, std::uint32_t value) {
  out.push_back(static_cast<char>((value >> 24) & 0xffu));
  out.push_back(static_cast<char>((value >> 16) & 0xffu));
  out.push_back(static_cast<char>((value >> 8) & 0xffu));
  out.push_back(static_cast<char>(value & 0xffu));
}

void append_chunk(std::string& out, std::string_view type, std::string_view data) {
  append_big_endian(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t type_start = out.size();
  out.append(type);
  out.append(data);
  append_big_endian(out, crc32(std::string_view(out).substr(type_start)));
}

// Writes bits least significant first, as deflate packs them.
class BitWriter {
 public:
  explicit BitWriter(std::string& out) : out_(out) {}
  void put(std::uint32_t bits, int count) {
    buffer_ |= std::uint64_t{bits} << pending_;
    pending_ += count;
    while (pending_ >= 8) {
      out_.push_back(static_cast<char>(buffer_ & 0xffu));
      buffer_ >>= 8;
      pending_ -= 8;
    }
  }
  // Huffman codes are defined most significant bit first.
  void put_code(std::uint32_t code, int count) {
    std::uint32_t reversed = 0;
    for (int i = 0; i < count; ++i) reversed |= ((code >> i) & 1u) << (count - 1 - i);
    put(reversed, count);
  }
  void flush() {
    if (pending_ > 0) out_.push_back(static_cast<char>(buffer_ & 0xffu));
    buffer_ = 0;
    pending_ = 0;
  }

 private:
  std::string& out_;
  std::uint64_t buffer_ = 0;
  int pending_ = 0;
};

constexpr std::array<std::uint16_t, 29> kLengthBase{3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                                    15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                                    67, 83, 99, 115, 131, 163, 195, 227, 258};
constexpr std::array<std::uint8_t, 29> kLengthExtraBits{0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                                        2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
constexpr std::array<std::uint16_t, 30> kDistanceBase{
    1,   2,   3,   4,   5,   7,    9,    13,   17,   25,   33,   49,   65,    97,    129,
    193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
constexpr std::array<std::uint8_t, 30> kDistanceExtraBits{0, 0, 0,  0,  1,  1,  2,  2,  3,  3,
                                                          4, 4, 5,  5,  6,  6,  7,  7,  8,  8,
                                                          9, 9, 10, 10, 11, 11, 12, 12, 13, 13};

// The fixed literal/length code of deflate (RFC 1951, 3.2.6).
void put_fixed_symbol(BitWriter& writer, std::uint32_t symbol) {
  if (symbol < 144) {
    writer.put_code(0x30 + symbol, 8);
  } else if (symbol < 256) {
    writer.put_code(0x190 + (symbol - 144), 9);
  } else if (symbol < 280) {
    writer.put_code(symbol - 256, 7);
  } else {
    writer.put_code(0xc0 + (symbol - 280), 8);
  }
}

// Index of the last entry of `bases` that is <= value.
template <std::size_t N>
std::size_t code_for(const std::array<std::uint16_t, N>& bases, std::uint32_t value) {
  return static_cast<std::size_t>(std::upper_bound(bases.begin(), bases.end(), value) -
                                  bases.begin()) -
         1;
}

void put_match(BitWriter& writer, std::uint32_t match_length, std::uint32_t distance) {
  const std::size_t length_code = code_for(kLengthBase, match_length);
  put_fixed_symbol(writer, 257 + static_cast<std::uint32_t>(length_code));
  writer.put(match_length - kLengthBase[length_code], kLengthExtraBits[length_code]);
  const std::size_t distance_code = code_for(kDistanceBase, distance);
  writer.put_code(static_cast<std::uint32_t>(distance_code), 5);
  writer.put(distance - kDistanceBase[distance_code], kDistanceExtraBits[distance_code]);
}

// One fixed-Huffman block with greedy LZ77 matching over hash chains. Rendered pictures are
// mostly flat colour, which this compresses by two orders of magnitude; dynamic Huffman codes
// would gain little more for their complexity.
std::string deflate_fixed(std::span<const std::uint8_t> data) {
  constexpr std::size_t kWindow = 32768;
  constexpr std::size_t kMinMatch = 3;
  constexpr std::size_t kMaxMatch = 258;
  constexpr int kHashBits = 15;
  constexpr int kMaxChain = 32;
  constexpr std::int64_t kNoPosition = -1;

  std::vector<std::int64_t> head(std::size_t{1} << kHashBits, kNoPosition);
  std::vector<std::int64_t> previous(kWindow, kNoPosition);
  auto hash_at = [&](std::size_t i) {
    const std::uint32_t key = (std::uint32_t{data[i]} << 16) | (std::uint32_t{data[i + 1]} << 8) |
                              std::uint32_t{data[i + 2]};
    return static_cast<std::size_t>((key * 2654435761u) >> (32 - kHashBits));
  };
  auto insert = [&](std::size_t i) {
    if (i + kMinMatch > data.size()) return;
    const std::size_t hash = hash_at(i);
    previous[i % kWindow] = head[hash];
    head[hash] = static_cast<std::int64_t>(i);
  };

  std::string out;
  out.reserve(data.size() / 8 + 64);
  BitWriter writer(out);
  writer.put(1, 1);  // final block
  writer.put(1, 2);  // fixed Huffman codes
  std::size_t i = 0;
  while (i < data.size()) {
    std::size_t best_length = 0;
    std::size_t best_distance = 0;
    if (i + kMinMatch <= data.size()) {
      const std::size_t longest = std::min(kMaxMatch, data.size() - i);
      std::int64_t candidate = head[hash_at(i)];
      for (int chain = 0; chain < kMaxChain && candidate != kNoPosition; ++chain) {
        const auto start = static_cast<std::size_t>(candidate);
        if (i - start > kWindow) break;
        std::size_t match = 0;
        while (match < longest && data[start + match] == data[i + match]) ++match;
        if (match > best_length) {
          best_length = match;
          best_distance = i - start;
          if (match == longest) break;
        }
        candidate = previous[start % kWindow];
      }
    }
    if (best_length >= kMinMatch) {
      put_match(writer, static_cast<std::uint32_t>(best_length),
                static_cast<std::uint32_t>(best_distance));
      for (std::size_t k = 0; k < best_length; ++k) insert(i + k);
      i += best_length;
    } else {
      put_fixed_symbol(writer, data[i]);
      insert(i);
      ++i;
    }
  }
  put_fixed_symbol(writer, 256);  // end of block
  writer.flush();
  return out;
}

std::string deflate_stored(std::span<const std::uint8_t> data) {
  constexpr std::size_t kMaxStoredBlock = 65535;
  std::string out;
  std::size_t start = 0;
  do {
    const std::size_t size = std::min(kMaxStoredBlock, data.size() - start);
    const bool final_block = start + size == data.size();
    out.push_back(static_cast<char>(final_block ? 1 : 0));  // BFINAL, BTYPE = 00, then align
    const auto length = static_cast<std::uint16_t>(size);
    const auto complement = static_cast<std::uint16_t>(~length);
    out.push_back(static_cast<char>(length & 0xffu));
    out.push_back(static_cast<char>(length >> 8));
    out.push_back(static_cast<char>(complement & 0xffu));
    out.push_back(static_cast<char>(complement >> 8));
    out.append(reinterpret_cast<const char*>(data.data() + start), size);
    start += size;
  } while (start < data.size());
  return out;
}

std::string zlib_compress(std::span<const std::uint8_t> data) {
  std::string deflated = deflate_fixed(data);
  // Noise-like pictures do not compress; never store more than the raw size plus block headers.
  if (deflated.size() > data.size() + data.size() / 65535 * 5 + 5) deflated = deflate_stored(data);
  std::string out;
  out.reserve(deflated.size() + 6);
  out.push_back(static_cast<char>(0x78));  // deflate, 32 KiB window
  out.push_back(static_cast<char>(0x01));  // no dictionary, check bits: 0x7801 % 31 == 0
  out += deflated;
  append_big_endian(out, adler32(data));
  return out;
}

std::uint8_t paeth_predictor(int left, int above, int upper_left) {
  const int estimate = left + above - upper_left;
  const int to_left = std::abs(estimate - left);
  const int to_above = std::abs(estimate - above);
  const int to_upper_left = std::abs(estimate - upper_left);
  if (to_left <= to_above && to_left <= to_upper_left) return static_cast<std::uint8_t>(left);
  if (to_above <= to_upper_left) return static_cast<std::uint8_t>(above);
  return static_cast<std::uint8_t>(upper_left);
}

// Each scanline gets the filter whose output has the smallest sum of absolute (signed) values,
// the heuristic the PNG specification recommends for truecolour.
std::vector<std::uint8_t> filter_scanlines(std::span<const std::uint8_t> rgb, int width,
                                           int height) {
  constexpr std::size_t kBytesPerPixel = 3;
  const std::size_t row_bytes = static_cast<std::size_t>(width) * kBytesPerPixel;
  std::vector<std::uint8_t> filtered;
  filtered.reserve((row_bytes + 1) * static_cast<std::size_t>(height));
  const std::vector<std::uint8_t> zero_row(row_bytes, 0);
  std::array<std::vector<std::uint8_t>, 5> candidates;
  for (auto& candidate : candidates) candidate.resize(row_bytes);

  for (int y = 0; y < height; ++y) {
    const std::uint8_t* row = rgb.data() + static_cast<std::size_t>(y) * row_bytes;
    const std::uint8_t* above = y > 0 ? row - row_bytes : zero_row.data();
    for (std::size_t i = 0; i < row_bytes; ++i) {
      const int left = i >= kBytesPerPixel ? row[i - kBytesPerPixel] : 0;
      const int upper_left = i >= kBytesPerPixel ? above[i - kBytesPerPixel] : 0;
      candidates[0][i] = row[i];
      candidates[1][i] = static_cast<std::uint8_t>(row[i] - left);
      candidates[2][i] = static_cast<std::uint8_t>(row[i] - above[i]);
      candidates[3][i] = static_cast<std::uint8_t>(row[i] - (left + above[i]) / 2);
      candidates[4][i] =
          static_cast<std::uint8_t>(row[i] - paeth_predictor(left, above[i], upper_left));
    }
    std::size_t best_filter = 0;
    std::uint64_t best_cost = std::numeric_limits<std::uint64_t>::max();
    for (std::size_t filter = 0; filter < candidates.size(); ++filter) {
      std::uint64_t cost = 0;
      for (const std::uint8_t value : candidates[filter]) {
        cost +=
            static_cast<std::uint64_t>(std::abs(static_cast<int>(static_cast<std::int8_t>(value))));
      }
      if (cost < best_cost) {
        best_cost = cost;
        best_filter = filter;
      }
    }
    filtered.push_back(static_cast<std::uint8_t>(best_filter));
    filtered.insert(filtered.end(), candidates[best_filter].begin(), candidates[best_filter].end());
  }
  return filtered;
}

// The camera of a picture of the mesh (supersampled); false, leaving `camera` as it is, when
// there is no triangle to frame.
bool picture_camera(const Mesh& mesh, const RenderOptions& options, Camera& camera) {
  Vec3 low;
  Vec3 high;
  if (!bounding_box_of_triangles(mesh, low, high)) return false;
  if (options.frame_box) {
    low = (*options.frame_box)[0];
    high = (*options.frame_box)[1];
  }
  camera = make_camera(low, high, options, options.width * options.supersample,
                       options.height * options.supersample);
  return true;
}

}  // namespace

std::vector<std::uint8_t> render_mesh(const Mesh& mesh,
                                      std::span<const std::array<std::uint8_t, 3>> face_colors,
                                      const RenderOptions& options) {
  validate_options(options);
  if (!face_colors.empty() && face_colors.size() != mesh.face_count()) {
    throw InvalidInputError("render_mesh: " + std::to_string(face_colors.size()) +
                            " face colours for " + std::to_string(mesh.face_count()) + " faces");
  }
  const int sample_width = options.width * options.supersample;
  const int sample_height = options.height * options.supersample;
  SampleBuffer buffer(sample_width, sample_height);

  Camera camera;
  if (picture_camera(mesh, options, camera)) {
    const std::vector<ProjectedVertex> projected = project_vertices(mesh, camera);
    const double edge_half_width_subpixels =
        options.edges || options.borders ? kEdgeHalfWidthPixels * options.supersample * kSubpixel
                                         : 0.0;
    const std::vector<EdgeMask> lines = options.edges     ? std::vector<EdgeMask>()
                                        : options.borders ? border_line_masks(mesh, face_colors)
                                                          : std::vector<EdgeMask>();
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const Triangle& triangle = mesh.triangles[t];
      rasterise_triangle(static_cast<std::uint32_t>(t), projected[triangle[0]],
                         projected[triangle[1]], projected[triangle[2]],
                         lines.empty() ? kAllEdges : lines[t], edge_half_width_subpixels, buffer);
    }
  }
  return resolve(buffer, mesh, face_colors, camera, options);
}

std::vector<std::array<double, 2>> project_to_picture(const Mesh& mesh,
                                                      std::span<const Vec3> points,
                                                      const RenderOptions& options) {
  validate_options(options);
  Camera camera;
  picture_camera(mesh, options, camera);
  std::vector<std::array<double, 2>> result(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 offset = subtract(points[i], camera.centre);
    result[i] = {(camera.half_width + dot(offset, camera.right) * camera.samples_per_unit) /
                     options.supersample,
                 (camera.half_height - dot(offset, camera.up) * camera.samples_per_unit) /
                     options.supersample};
  }
  return result;
}

std::string encode_png(std::span<const std::uint8_t> rgb, int width, int height) {
  if (width < 1 || height < 1) {
    throw InvalidInputError("encode_png: width and height must be positive");
  }
  const std::size_t expected =
      static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3;
  if (rgb.size() != expected) {
    throw InvalidInputError("encode_png: " + std::to_string(rgb.size()) + " bytes for a " +
                            std::to_string(width) + "x" + std::to_string(height) +
                            " RGB picture (expected " + std::to_string(expected) + ")");
  }

  std::string png("\x89PNG\r\n\x1a\n", 8);

  std::string header;
  append_big_endian(header, static_cast<std::uint32_t>(width));
  append_big_endian(header, static_cast<std::uint32_t>(height));
  header.push_back(8);  // bit depth
  header.push_back(2);  // colour type: truecolour
  header.push_back(0);  // compression: deflate
  header.push_back(0);  // filter method: adaptive
  header.push_back(0);  // no interlace
  append_chunk(png, "IHDR", header);

  const std::string compressed = zlib_compress(filter_scanlines(rgb, width, height));
  // Several IDAT chunks keep each one far below the 2^31 chunk length limit.
  constexpr std::size_t kMaxIdatSize = std::size_t{1} << 20;
  for (std::size_t start = 0; start < compressed.size(); start += kMaxIdatSize) {
    append_chunk(png, "IDAT", std::string_view(compressed).substr(start, kMaxIdatSize));
  }
  append_chunk(png, "IEND", {});
  return png;
}

void write_png(const std::filesystem::path& path, std::span<const std::uint8_t> rgb, int width,
               int height) {
  detail::write_file_atomically(path, encode_png(rgb, width, height));
}

void write_png(const std::filesystem::path& path, const Mesh& mesh,
               std::span<const std::array<std::uint8_t, 3>> face_colors,
               const RenderOptions& options) {
  const std::vector<std::uint8_t> rgb = render_mesh(mesh, face_colors, options);
  write_png(path, rgb, options.width, options.height);
}

}  // namespace primseg
