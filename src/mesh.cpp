#include "primseg/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include "huge_pages.hpp"
#include "primseg/error.hpp"

namespace primseg {
namespace {

struct Point2 {
  double x;
  double y;
};

double cross(const Point2& origin, const Point2& a, const Point2& b) {
  return (a.x - origin.x) * (b.y - origin.y) - (a.y - origin.y) * (b.x - origin.x);
}

bool same_point(const Point2& a, const Point2& b) {
  return a.x == b.x && a.y == b.y;
}

// Closed test: a point on the boundary of the ear also blocks it, since clipping that ear would
// create a diagonal touching the polygon boundary.
bool inside_or_on_triangle(const Point2& p, const Point2& a, const Point2& b, const Point2& c) {
  return cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0;
}

Vec3 newell_normal(std::span<const std::uint32_t> loop, const std::vector<Vec3>& positions) {
  Vec3 normal{0.0, 0.0, 0.0};
  // Relative to the first vertex, so that far-from-origin polygons keep their precision.
  const Vec3& origin = positions[loop[0]];
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec3& p = positions[loop[i]];
    const Vec3& q = positions[loop[(i + 1) % loop.size()]];
    const double px = p[0] - origin[0], py = p[1] - origin[1], pz = p[2] - origin[2];
    const double qx = q[0] - origin[0], qy = q[1] - origin[1], qz = q[2] - origin[2];
    normal[0] += (py - qy) * (pz + qz);
    normal[1] += (pz - qz) * (px + qx);
    normal[2] += (px - qx) * (py + qy);
  }
  return normal;
}

/// Triangulates polygons by ear clipping; owns scratch buffers so that a mesh of many polygons
/// triggers no per-polygon allocation.
///
/// An ear is blocked by a reflex vertex inside it. Scanning the whole loop for one made large
/// polygons quadratic (a wavy outline of 100,000 vertices took 11 s, and a spiral strip of
/// 20,000 ran out of budget after 13 s and was fanned into overlapping triangles). The reflex
/// vertices of a large polygon are filed in a uniform grid over its projection, about one vertex
/// per cell, and an ear looks only in the cells its triangle covers. The test, and so the
/// triangulation, is the same either way (bench/pathological.sh times both shapes).
class EarClipper {
 public:
  /// Appends loop.size() - 2 triangles of `loop` to `triangles`, oriented like the loop.
  void triangulate(std::span<const std::uint32_t> loop, const std::vector<Vec3>& positions,
                   std::vector<Triangle>& triangles) {
    const std::size_t n = loop.size();
    corners_.assign(loop.begin(), loop.end());
    next_.resize(n);
    previous_.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
      next_[i] = i + 1 == n ? 0 : i + 1;
      previous_[i] = i == 0 ? static_cast<std::uint32_t>(n - 1) : i - 1;
    }
    const Vec3 normal = newell_normal(loop, positions);
    const double length =
        std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
    if (length > 0.0 && std::isfinite(length)) {
      project(normal, length, loop, positions);
      build_grid();
      clip_ears(n, triangles);
    } else {
      // Zero-area polygon: no plane to clip in, and every split is as good as another.
      fan(0, n, triangles);
    }
  }

 private:
  // Projects the loop on a basis (u, v) with u x v along the Newell normal, which makes the
  // projected loop counter-clockwise.
  void project(const Vec3& normal, double length, std::span<const std::uint32_t> loop,
               const std::vector<Vec3>& positions) {
    const Vec3 n{normal[0] / length, normal[1] / length, normal[2] / length};
    // Any vector not parallel to n seeds u: use the axis along n's smallest component.
    Vec3 seed{0.0, 0.0, 0.0};
    const int smallest = std::fabs(n[0]) <= std::fabs(n[1])
                             ? (std::fabs(n[0]) <= std::fabs(n[2]) ? 0 : 2)
                             : (std::fabs(n[1]) <= std::fabs(n[2]) ? 1 : 2);
    seed[smallest] = 1.0;
    Vec3 u{n[1] * seed[2] - n[2] * seed[1], n[2] * seed[0] - n[0] * seed[2],
           n[0] * seed[1] - n[1] * seed[0]};
    const double u_length = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (double& c : u) c /= u_length;
    const Vec3 v{n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};

    // Relative to the first vertex, so that far-from-origin polygons keep their precision.
    const Vec3& origin = positions[loop[0]];
    projected_.clear();
    for (const std::uint32_t vertex : loop) {
      const Vec3& p = positions[vertex];
      const double dx = p[0] - origin[0], dy = p[1] - origin[1], dz = p[2] - origin[2];
      projected_.push_back({dx * u[0] + dy * u[1] + dz * u[2], dx * v[0] + dy * v[1] + dz * v[2]});
    }
  }

  // Below this many vertices the scan of the loop costs less than filing them.
  static constexpr std::size_t kGridMinVertices = 64;

  void build_grid() {
    const std::size_t n = projected_.size();
    grid_columns_ = 0;
    if (n < kGridMinVertices) return;
    Point2 low = projected_[0], high = low;
    for (const Point2& p : projected_) {
      low = {std::min(low.x, p.x), std::min(low.y, p.y)};
      high = {std::max(high.x, p.x), std::max(high.y, p.y)};
    }
    const double width = high.x - low.x, height = high.y - low.y;
    if (!(width > 0.0 && height > 0.0 && std::isfinite(width) && std::isfinite(height))) return;
    // About one vertex per cell, the cells as square as the box allows.
    const double columns =
        std::clamp(std::round(std::sqrt(double(n) * width / height)), 1.0, double(n));
    grid_columns_ = static_cast<std::size_t>(columns);
    grid_rows_ = std::max<std::size_t>(1, n / grid_columns_);
    grid_low_ = low;
    grid_scale_ = {double(grid_columns_) / width, double(grid_rows_) / height};
    // Room in each cell for every vertex that falls in it; the reflex ones are filed as they
    // become reflex (update_reflex), and taken out when they stop being (or are clipped).
    cell_start_.assign(grid_columns_ * grid_rows_ + 1, 0);
    for (const Point2& p : projected_) ++cell_start_[cell(p) + 1];
    for (std::size_t c = 0; c + 1 < cell_start_.size(); ++c) cell_start_[c + 1] += cell_start_[c];
    cell_vertices_.resize(n);
    cell_size_.assign(grid_columns_ * grid_rows_, 0);
    slot_.resize(n);
  }

  void file_in_grid(std::uint32_t j) {
    const std::size_t c = cell(projected_[j]);
    slot_[j] = cell_start_[c] + cell_size_[c]++;
    cell_vertices_[slot_[j]] = j;
  }
  void take_out_of_grid(std::uint32_t j) {
    const std::size_t c = cell(projected_[j]);
    const std::size_t last = cell_start_[c] + --cell_size_[c];
    cell_vertices_[slot_[j]] = cell_vertices_[last];
    slot_[cell_vertices_[last]] = slot_[j];
  }

  // The column or row of a coordinate, clamped to the grid (a monotone map, so that every point
  // of a box is filed in a cell between those of the box's corners).
  static std::size_t grid_index(double coordinate, double low, double scale, std::size_t count) {
    const double index = (coordinate - low) * scale;
    if (!(index > 0.0)) return 0;
    return index >= double(count - 1) ? count - 1 : static_cast<std::size_t>(index);
  }
  std::size_t column(double x) const {
    return grid_index(x, grid_low_.x, grid_scale_.x, grid_columns_);
  }
  std::size_t row(double y) const { return grid_index(y, grid_low_.y, grid_scale_.y, grid_rows_); }
  std::size_t cell(const Point2& p) const { return row(p.y) * grid_columns_ + column(p.x); }
  static std::size_t widened_down(std::size_t index) { return index > 0 ? index - 1 : 0; }

  // Ears whose smallest angle has a sine below this (t / longest side squared bounds it) are
  // tested along the loop.
  static constexpr double kFlatEar = 1e-8;

  static double longest_squared_side(const Point2& a, const Point2& b, const Point2& c) {
    const auto squared = [](const Point2& p, const Point2& q) {
      return (p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y);
    };
    return std::max({squared(a, b), squared(b, c), squared(c, a)});
  }

  // Boxes of more cells than this are walked over the triangle's own columns, row by row.
  static constexpr std::size_t kSpanMinCells = 16;

  // The smallest and largest x of triangle (a, b, c) between heights y0 < y1: its corners in the
  // band and where its edges cross the band's sides. Empty (low > high) if it misses the band.
  static std::pair<double, double> triangle_span(const Point2& a, const Point2& b, const Point2& c,
                                                 double y0, double y1) {
    double low = std::numeric_limits<double>::infinity(), high = -low;
    const auto take = [&](double x) {
      low = std::min(low, x);
      high = std::max(high, x);
    };
    for (const Point2* corner : {&a, &b, &c})
      if (corner->y >= y0 && corner->y <= y1) take(corner->x);
    for (const auto& [p, q] : {std::pair{&a, &b}, std::pair{&b, &c}, std::pair{&c, &a}})
      for (const double y : {y0, y1})
        if ((p->y < y) != (q->y < y)) take(p->x + (y - p->y) * (q->x - p->x) / (q->y - p->y));
    return {low, high};
  }

  // Whether reflex vertex j, other than the ear's corners and their copies, blocks ear (a, i, c).
  bool blocks(std::uint32_t j, std::uint32_t i, const Point2& a, const Point2& b,
              const Point2& c) const {
    if (!reflex_[j] || j == i || j == previous_[i] || j == next_[i]) return false;
    const Point2& p = projected_[j];
    // Copies of a corner (e.g. a bridge to a hole) do not block the ear.
    if (same_point(p, a) || same_point(p, b) || same_point(p, c)) return false;
    return inside_or_on_triangle(p, a, b, c);
  }

  double turn(std::uint32_t i) const {
    return cross(projected_[previous_[i]], projected_[i], projected_[next_[i]]);
  }

  // Only reflex (or flat) vertices can lie in an ear, so convex stretches cost nothing to check.
  bool is_ear(std::uint32_t i, bool allow_flat, std::size_t remaining) {
    ++work_;  // The walk itself: a spiral's is quadratic, its ears clipped a few per lap.
    const double t = turn(i);
    if (allow_flat ? t < 0.0 : t <= 0.0) return false;
    if (reflex_count_ == 0) return true;
    const Point2& a = projected_[previous_[i]];
    const Point2& b = projected_[i];
    const Point2& c = projected_[next_[i]];
    // The closed test holds the points of the triangle and, through round-off, points within
    // about 1e-16 / sin(smallest angle) of its sides' lines. A cell around its box takes in
    // those of a proper triangle; a flat or nearly flat one (allow_flat, collinear corners up to
    // round-off) holds points all along its line, which only the loop has.
    if (grid_columns_ > 0 && t > kFlatEar * longest_squared_side(a, b, c)) {
      const std::size_t first_column = widened_down(column(std::min({a.x, b.x, c.x})));
      const std::size_t last_column =
          std::min(column(std::max({a.x, b.x, c.x})) + 1, grid_columns_ - 1);
      const std::size_t first_row = widened_down(row(std::min({a.y, b.y, c.y})));
      const std::size_t last_row = std::min(row(std::max({a.y, b.y, c.y})) + 1, grid_rows_ - 1);
      const std::size_t rows = last_row - first_row + 1;
      const std::size_t cells = (last_column - first_column + 1) * rows;
      // A large box (the fan a convex stretch of the outline grows into is a long sliver) is
      // walked row by row over the triangle's own columns. Once few vertices are left, the loop
      // is the shorter walk.
      const bool by_span = cells > kSpanMinCells;
      if (2 * (by_span ? 3 * rows : cells) < remaining) {
        for (std::size_t r = first_row; r <= last_row; ++r) {
          std::size_t from = first_column, to = last_column;
          if (by_span) {
            // The triangle's part in the row's band widened by a row on each side, and its
            // columns by one, so that round-off never leaves a point of the triangle out.
            const auto [low_x, high_x] =
                triangle_span(a, b, c, grid_low_.y + (double(r) - 1.0) / grid_scale_.y,
                              grid_low_.y + (double(r) + 2.0) / grid_scale_.y);
            if (low_x <= high_x) {
              from = std::max(first_column, widened_down(column(low_x)));
              to = std::min(last_column, column(high_x) + 1);
            }
          }
          const std::size_t row_start = r * grid_columns_;
          work_ += (by_span ? 4 : 0) + 1 + to - from;
          for (std::size_t cell = row_start + from; cell <= row_start + to; ++cell)
            for (std::size_t k = cell_start_[cell]; k < cell_start_[cell] + cell_size_[cell]; ++k) {
              ++work_;
              if (blocks(cell_vertices_[k], i, a, b, c)) return false;
            }
        }
        return true;
      }
    }
    work_ += remaining;
    for (std::uint32_t j = next_[next_[i]]; j != previous_[i]; j = next_[j])
      if (blocks(j, i, a, b, c)) return false;
    return true;
  }

  void set_reflex(std::uint32_t i, bool reflex) {
    if (reflex == reflex_[i]) return;
    reflex_[i] = reflex;
    if (reflex) {
      ++reflex_count_;
      if (grid_columns_ > 0) file_in_grid(i);
    } else {
      --reflex_count_;
      if (grid_columns_ > 0) take_out_of_grid(i);
    }
  }
  void update_reflex(std::uint32_t i) { set_reflex(i, turn(i) <= 0.0); }

  void clip_ears(std::size_t n, std::vector<Triangle>& triangles) {
    reflex_.assign(n, false);
    reflex_count_ = 0;
    for (std::uint32_t i = 0; i < n; ++i) update_reflex(i);
    // The budget bounds pathological polygons (a spiral strip of 100,000 vertices clips a few
    // ears per lap of the loop), which then get the fan fallback for what is left of them: at
    // most 2^32 steps and vertex tests, about 25 s.
    const std::size_t bounded_n = std::min<std::size_t>(n, std::size_t{1} << 14);
    const std::size_t budget =
        std::max<std::size_t>(std::size_t{1} << 22, 16 * bounded_n * bounded_n);
    work_ = 0;
    std::size_t remaining = n;
    std::uint32_t i = 0;
    std::size_t misses = 0;
    // Flat ears (collinear or repeated vertices) are clipped only when no proper ear is left.
    bool allow_flat = false;
    while (remaining > 3 && work_ < budget) {
      if (!is_ear(i, allow_flat, remaining)) {
        i = next_[i];
        if (++misses < remaining) continue;
        if (allow_flat) break;  // Self-intersecting or numerically hopeless: fan the rest.
        allow_flat = true;
        misses = 0;
        continue;
      }
      const std::uint32_t before = previous_[i];
      const std::uint32_t after = next_[i];
      triangles.push_back({corners_[before], corners_[i], corners_[after]});
      next_[before] = after;
      previous_[after] = before;
      set_reflex(i, false);
      --remaining;
      update_reflex(before);
      update_reflex(after);
      i = after;
      misses = 0;
      allow_flat = false;
    }
    fan(i, remaining, triangles);
  }

  // Fans the `count` vertices left in the linked loop, starting at `first`.
  void fan(std::uint32_t first, std::size_t count, std::vector<Triangle>& triangles) const {
    std::uint32_t b = next_[first];
    for (std::size_t k = 2; k < count; ++k) {
      triangles.push_back({corners_[first], corners_[b], corners_[next_[b]]});
      b = next_[b];
    }
  }

  std::vector<std::uint32_t> corners_;  // Vertex ids, in loop order.
  std::vector<Point2> projected_;
  std::vector<std::uint32_t> next_;
  std::vector<std::uint32_t> previous_;
  std::vector<bool> reflex_;  // Turn <= 0: blocks ears it lies in.
  std::size_t reflex_count_ = 0;
  std::size_t work_ = 0;
  // The grid: cell (row, column) holds cell_vertices_[cell_start_[c] .. cell_start_[c + 1]),
  // c = row * grid_columns_ + column. No grid when grid_columns_ is 0.
  std::size_t grid_columns_ = 0;
  std::size_t grid_rows_ = 0;
  Point2 grid_low_{0.0, 0.0};
  Point2 grid_scale_{0.0, 0.0};
  std::vector<std::size_t> cell_start_;
  std::vector<std::uint32_t> cell_size_;      // reflex vertices filed in each cell
  std::vector<std::uint32_t> cell_vertices_;  // filed vertices, each cell's from its start
  std::vector<std::size_t> slot_;             // where a filed vertex is in cell_vertices_
};

[[noreturn]] void invalid(const std::string& message) {
  throw InvalidInputError(message);
}

void check_positions(const std::vector<Vec3>& positions) {
  if (positions.size() > std::numeric_limits<std::uint32_t>::max()) {
    invalid("mesh has " + std::to_string(positions.size()) +
            " vertices, more than 32-bit indices can address");
  }
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const Vec3& p = positions[v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      invalid("vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
  }
}

void check_polygons(const std::vector<std::uint32_t>& offsets,
                    const std::vector<std::uint32_t>& vertices, std::size_t vertex_count) {
  if (offsets.empty() || offsets.front() != 0) {
    invalid("polygon offsets must start with 0");
  }
  if (offsets.size() == 1) invalid("mesh has no faces");
  for (std::size_t f = 0; f + 1 < offsets.size(); ++f) {
    if (offsets[f + 1] < offsets[f] || offsets[f + 1] - offsets[f] < 3) {
      const long long size = static_cast<long long>(offsets[f + 1]) - offsets[f];
      invalid("face " + std::to_string(f) + " has " + std::to_string(size) +
              " vertices, fewer than 3");
    }
  }
  if (offsets.back() != vertices.size()) {
    invalid("polygon offsets end at " + std::to_string(offsets.back()) + " but there are " +
            std::to_string(vertices.size()) + " polygon vertices");
  }
  std::size_t face = 0;
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    if (vertices[i] >= vertex_count) {
      while (offsets[face + 1] <= i) ++face;
      invalid("face " + std::to_string(face) + " references vertex " + std::to_string(vertices[i]) +
              " but the mesh has " + std::to_string(vertex_count) + " vertices");
    }
  }
}

}  // namespace

Mesh Mesh::from_polygons(std::vector<Vec3> positions, std::vector<std::uint32_t> offsets,
                         std::vector<std::uint32_t> vertices) {
  check_positions(positions);
  check_polygons(offsets, vertices, positions.size());

  Mesh mesh;
  mesh.positions = std::move(positions);
  mesh.polygon_offsets = std::move(offsets);
  mesh.polygon_vertices = std::move(vertices);
  const std::uint32_t faces = mesh.face_count();
  const std::size_t triangle_estimate = mesh.polygon_vertices.size() - 2 * std::size_t{faces};
  detail::reserve_huge_to_fill(mesh.triangles, triangle_estimate);
  detail::reserve_huge_to_fill(mesh.face_of_triangle, triangle_estimate);

  EarClipper clipper;
  const std::uint32_t* corners = mesh.polygon_vertices.data();
  for (std::uint32_t f = 0; f < faces; ++f) {
    const std::uint32_t begin = mesh.polygon_offsets[f];
    const std::uint32_t end = mesh.polygon_offsets[f + 1];
    if (end - begin == 3) {
      mesh.triangles.push_back({corners[begin], corners[begin + 1], corners[begin + 2]});
      mesh.face_of_triangle.push_back(f);
      continue;
    }
    clipper.triangulate(mesh.polygon(f), mesh.positions, mesh.triangles);
    mesh.face_of_triangle.resize(mesh.triangles.size(), f);
  }
  return mesh;
}

Mesh Mesh::from_triangles(std::vector<Vec3> positions, std::vector<Triangle> triangles) {
  check_positions(positions);
  if (triangles.empty()) invalid("mesh has no faces");
  if (triangles.size() > std::numeric_limits<std::uint32_t>::max() / 3) {
    invalid("mesh has " + std::to_string(triangles.size()) +
            " triangles, more than 32-bit offsets can address");
  }
  Mesh mesh;
  // A fresh vector, not a resize of the default {0}: g++ 12 warns falsely about the latter.
  std::vector<std::uint32_t> offsets;
  detail::resize_huge(offsets, triangles.size() + 1);
  mesh.polygon_offsets = std::move(offsets);
  detail::reserve_huge_to_fill(mesh.polygon_vertices, 3 * triangles.size());
  detail::resize_huge(mesh.face_of_triangle, triangles.size());
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    for (std::uint32_t corner : triangles[t]) {
      if (corner >= positions.size()) {
        invalid("face " + std::to_string(t) + " references vertex " + std::to_string(corner) +
                " but the mesh has " + std::to_string(positions.size()) + " vertices");
      }
      mesh.polygon_vertices.push_back(corner);
    }
    mesh.polygon_offsets[t + 1] = 3 * (t + 1);
    mesh.face_of_triangle[t] = t;
  }
  mesh.positions = std::move(positions);
  mesh.triangles = std::move(triangles);
  return mesh;
}

void Mesh::validate() const {
  check_positions(positions);
  check_polygons(polygon_offsets, polygon_vertices, positions.size());
  if (face_of_triangle.size() != triangles.size()) {
    invalid("mesh has " + std::to_string(triangles.size()) + " triangles but " +
            std::to_string(face_of_triangle.size()) + " face_of_triangle entries");
  }
  const std::uint32_t faces = face_count();
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (std::uint32_t corner : triangles[t]) {
      if (corner >= positions.size()) {
        invalid("triangle " + std::to_string(t) + " references vertex " + std::to_string(corner) +
                " but the mesh has " + std::to_string(positions.size()) + " vertices");
      }
    }
    // Non-decreasing with steps of at most one from face 0 means every face has a triangle.
    const std::uint32_t expected_low = t == 0 ? 0 : face_of_triangle[t - 1];
    const std::uint32_t face = face_of_triangle[t];
    if (face < expected_low || face > expected_low + (t == 0 ? 0 : 1) || face >= faces) {
      invalid("face_of_triangle[" + std::to_string(t) + "] = " + std::to_string(face) +
              " breaks the order of faces (each face needs at least one triangle, in order)");
    }
  }
  if (triangles.empty()) invalid("mesh has faces but no triangles");
  if (face_of_triangle.back() + 1 != faces) {
    invalid("faces after face " + std::to_string(face_of_triangle.back()) + " have no triangles");
  }
}

namespace {

// Axis-aligned bounds of the vertices used by some face (indices out of range skipped, for the
// callers that take meshes unvalidated); low > high on every axis when there are none.
std::pair<Vec3, Vec3> face_vertex_bounds(const Mesh& mesh) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  Vec3 low{kInfinity, kInfinity, kInfinity}, high{-kInfinity, -kInfinity, -kInfinity};
  for (const std::uint32_t vertex : mesh.polygon_vertices) {
    if (vertex >= mesh.positions.size()) continue;
    const Vec3& p = mesh.positions[vertex];
    for (int axis = 0; axis < 3; ++axis) {
      low[axis] = std::min(low[axis], p[axis]);
      high[axis] = std::max(high[axis], p[axis]);
    }
  }
  return {low, high};
}

}  // namespace

double bounding_box_diagonal(const Mesh& mesh) {
  if (mesh.polygon_vertices.empty()) return 0.0;
  const auto [low, high] = face_vertex_bounds(mesh);
  const double dx = high[0] - low[0], dy = high[1] - low[1], dz = high[2] - low[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

Vec3 bounding_box_centre(const Mesh& mesh) {
  if (mesh.polygon_vertices.empty()) return {0, 0, 0};
  const auto [low, high] = face_vertex_bounds(mesh);
  // low + half the extent, not (low + high) / 2: no overflow near the largest doubles.
  return {low[0] + (high[0] - low[0]) / 2, low[1] + (high[1] - low[1]) / 2,
          low[2] + (high[2] - low[2]) / 2};
}

void check_geometric_range(const Mesh& mesh) {
  auto formatted = [](double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", x);
    return std::string(text);
  };
  for (std::size_t v = 0; v < mesh.positions.size(); ++v)
    for (const double x : mesh.positions[v])
      if (!(std::abs(x) <= kMaxCoordinateMagnitude))
        invalid("vertex " + std::to_string(v) + " has a coordinate of magnitude " +
                formatted(std::abs(x)) + ", above the " + formatted(kMaxCoordinateMagnitude) +
                " that primseg computes with");
  const auto [low, high] = face_vertex_bounds(mesh);
  double extent = 0;
  for (int axis = 0; axis < 3; ++axis)
    if (low[axis] <= high[axis]) extent = std::max(extent, high[axis] - low[axis]);
  if (extent > 0 && extent < kMinPositiveExtent)
    invalid("the mesh spans " + formatted(extent) + " units, below the " +
            formatted(kMinPositiveExtent) + " that primseg computes with");
}

}  // namespace primseg
