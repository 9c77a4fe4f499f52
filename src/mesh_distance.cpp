#include "primseg/mesh_distance.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "parallel.hpp"
#include "primseg/error.hpp"
#include "shape_generator/random.hpp"

namespace primseg {
namespace {

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec3 along(const Vec3& origin, const Vec3& direction, double t) {
  return {origin[0] + direction[0] * t, origin[1] + direction[1] * t, origin[2] + direction[2] * t};
}
double squared_distance(const Vec3& a, const Vec3& b) {
  const Vec3 d = sub(a, b);
  return dot(d, d);
}

Vec3 closest_point_on_segment(const Vec3& x, const Vec3& a, const Vec3& b) {
  const Vec3 ab = sub(b, a);
  const double length2 = dot(ab, ab);
  if (length2 == 0) return a;
  return along(a, ab, std::clamp(dot(sub(x, a), ab) / length2, 0.0, 1.0));
}

constexpr std::uint32_t kLeafSize = 4;

struct Box {
  Vec3 low{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
           std::numeric_limits<double>::infinity()};
  Vec3 high{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
            -std::numeric_limits<double>::infinity()};
  void add(const Vec3& p) {
    for (int k = 0; k < 3; ++k) {
      low[k] = std::min(low[k], p[k]);
      high[k] = std::max(high[k], p[k]);
    }
  }
  double squared_distance_to(const Vec3& p) const {
    double sum = 0;
    for (int k = 0; k < 3; ++k) {
      // Two-argument maxima: the initializer-list form went through an out-of-line max_element
      // in the sanitizer build (a tenth of a distance query's time there).
      const double outside = std::max(std::max(low[k] - p[k], p[k] - high[k]), 0.0);
      sum += outside * outside;
    }
    return sum;
  }
};

// Ericson's Voronoi-region walk; exact for triangles of some width, unreliable for slivers
// (returns a point of the triangle, but maybe not the nearest).
Vec3 voronoi_closest_point(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Voronoi regions of the corners, then of the edges, then the interior (barycentric).
  const Vec3 ab = sub(b, a), ac = sub(c, a), ax = sub(x, a);
  const double d1 = dot(ab, ax), d2 = dot(ac, ax);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bx = sub(x, b);
  const double d3 = dot(ab, bx), d4 = dot(ac, bx);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return along(a, ab, d1 / (d1 - d3));
  const Vec3 cx = sub(x, c);
  const double d5 = dot(ab, cx), d6 = dot(ac, cx);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return along(a, ac, d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return along(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denominator = va + vb + vc;
  if (!(denominator > 0)) return a;  // degenerate: the caller checks the edges
  const double v = vb / denominator, w = vc / denominator;
  return {a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w, a[2] + ab[2] * v + ac[2] * w};
}

}  // namespace

Vec3 closest_point_on_triangle(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 candidate = voronoi_closest_point(x, a, b, c);
  const Vec3 ab = sub(b, a), ac = sub(c, a);
  const Vec3 n = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2],
                  ab[0] * ac[1] - ab[1] * ac[0]};
  // A sliver (corner angles below about 1e-6 rad): the nearest of the candidate and the edges.
  if (dot(n, n) > 1e-12 * dot(ab, ab) * dot(ac, ac)) return candidate;
  const std::array<Vec3, 4> candidates = {candidate, closest_point_on_segment(x, a, b),
                                          closest_point_on_segment(x, b, c),
                                          closest_point_on_segment(x, c, a)};
  const Vec3* best = &candidates[0];
  for (const Vec3& p : candidates)
    if (squared_distance(x, p) < squared_distance(x, *best)) best = &p;
  return *best;
}

struct TriangleBvh::Impl {
  struct Node {
    Box box;
    // Leaf: triangles [first, first + count) of `order`. Inner: children at first and first + 1.
    std::uint32_t first = 0;
    std::uint32_t count = 0;  // 0 for an inner node
  };
  std::vector<std::array<Vec3, 3>> corners;  // per triangle, in mesh order
  std::vector<std::uint32_t> order;          // triangle indices, grouped by leaf
  std::vector<Node> nodes;

  void build(std::uint32_t node, std::uint32_t first, std::uint32_t count,
             std::vector<Vec3>& centroids) {
    Box box, centroid_box;
    for (std::uint32_t i = first; i < first + count; ++i) {
      for (const Vec3& p : corners[order[i]]) box.add(p);
      centroid_box.add(centroids[order[i]]);
    }
    nodes[node].box = box;
    if (count <= kLeafSize) {
      nodes[node].first = first;
      nodes[node].count = count;
      return;
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (centroid_box.high[k] - centroid_box.low[k] >
          centroid_box.high[axis] - centroid_box.low[axis])
        axis = k;
    const std::uint32_t half = count / 2;
    // A strict total order (ties by index), so the two halves are the same sets everywhere.
    std::nth_element(order.begin() + first, order.begin() + first + half,
                     order.begin() + first + count, [&](std::uint32_t s, std::uint32_t t) {
                       const double cs = centroids[s][axis], ct = centroids[t][axis];
                       return cs < ct || (cs == ct && s < t);
                     });
    const auto children = static_cast<std::uint32_t>(nodes.size());
    nodes.emplace_back();
    nodes.emplace_back();
    nodes[node].first = children;
    nodes[node].count = 0;
    build(children, first, half, centroids);
    build(children + 1, first + half, count - half, centroids);
  }
};

TriangleBvh::TriangleBvh(const Mesh& mesh) : impl_(std::make_unique<Impl>()) {
  if (mesh.triangles.empty())
    throw InvalidInputError("closest-point search: the mesh has no triangle");
  impl_->corners.reserve(mesh.triangles.size());
  std::vector<Vec3> centroids;
  centroids.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    for (const std::uint32_t v : t)
      if (v >= mesh.positions.size())
        throw InvalidInputError("closest-point search: a triangle indexes vertex " +
                                std::to_string(v) + " of " + std::to_string(mesh.positions.size()));
    const std::array<Vec3, 3> c = {mesh.positions[t[0]], mesh.positions[t[1]],
                                   mesh.positions[t[2]]};
    impl_->corners.push_back(c);
    centroids.push_back({(c[0][0] + c[1][0] + c[2][0]) / 3, (c[0][1] + c[1][1] + c[2][1]) / 3,
                         (c[0][2] + c[1][2] + c[2][2]) / 3});
  }
  impl_->order.resize(mesh.triangles.size());
  std::iota(impl_->order.begin(), impl_->order.end(), 0u);
  impl_->nodes.reserve(2 * mesh.triangles.size() / kLeafSize + 2);
  impl_->nodes.emplace_back();
  impl_->build(0, 0, mesh.triangle_count(), centroids);
}

TriangleBvh::~TriangleBvh() = default;
TriangleBvh::TriangleBvh(TriangleBvh&&) noexcept = default;
TriangleBvh& TriangleBvh::operator=(TriangleBvh&&) noexcept = default;

TriangleBvh::Hit TriangleBvh::closest_point(const Vec3& x) const {
  Hit best;
  best.squared_distance = std::numeric_limits<double>::infinity();
  best.triangle = std::numeric_limits<std::uint32_t>::max();
  // Depth is O(log T) (median splits), so a small fixed stack is enough for any 32-bit count.
  std::array<std::uint32_t, 128> stack;
  std::size_t top = 0;
  stack[top++] = 0;
  const auto& nodes = impl_->nodes;
  while (top > 0) {
    const Impl::Node& node = nodes[stack[--top]];
    // Equal distances are still visited: ties go to the lowest triangle index, whatever the tree.
    if (node.box.squared_distance_to(x) > best.squared_distance) continue;
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const std::uint32_t t = impl_->order[i];
        const auto& c = impl_->corners[t];
        const Vec3 p = closest_point_on_triangle(x, c[0], c[1], c[2]);
        const double d2 = squared_distance(x, p);
        if (d2 < best.squared_distance || (d2 == best.squared_distance && t < best.triangle))
          best = {p, d2, t};
      }
      continue;
    }
    const double near0 = nodes[node.first].box.squared_distance_to(x);
    const double near1 = nodes[node.first + 1].box.squared_distance_to(x);
    // Nearer child on top of the stack.
    if (near0 <= near1) {
      stack[top++] = node.first + 1;
      stack[top++] = node.first;
    } else {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
    }
  }
  return best;
}

namespace {

// Area-uniform samples: the triangle by inverse CDF of areas, the point by the square-root
// barycentric map (uniform on a triangle).
class SurfaceSampler {
 public:
  explicit SurfaceSampler(const Mesh& mesh) : mesh_(mesh) {
    cumulative_.reserve(mesh.triangles.size());
    double total = 0;
    for (const Triangle& t : mesh.triangles) {
      const Vec3 u = sub(mesh.positions[t[1]], mesh.positions[t[0]]);
      const Vec3 v = sub(mesh.positions[t[2]], mesh.positions[t[0]]);
      const Vec3 n = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                      u[0] * v[1] - u[1] * v[0]};
      total += 0.5 * std::sqrt(dot(n, n));
      cumulative_.push_back(total);
    }
  }
  double area() const { return cumulative_.empty() ? 0 : cumulative_.back(); }

  Vec3 sample(shape_detail::SplitMix64& random) const {
    const double target = random.uniform() * area();
    auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), target);
    if (it == cumulative_.end()) --it;
    const Triangle& t = mesh_.triangles[static_cast<std::size_t>(it - cumulative_.begin())];
    const double r1 = std::sqrt(random.uniform()), r2 = random.uniform();
    const double wa = 1 - r1, wb = r1 * (1 - r2), wc = r1 * r2;
    const Vec3& a = mesh_.positions[t[0]];
    const Vec3& b = mesh_.positions[t[1]];
    const Vec3& c = mesh_.positions[t[2]];
    return {wa * a[0] + wb * b[0] + wc * c[0], wa * a[1] + wb * b[1] + wc * c[1],
            wa * a[2] + wb * b[2] + wc * c[2]};
  }

 private:
  const Mesh& mesh_;
  std::vector<double> cumulative_;
};

std::uint64_t sample_count(const DistanceOptions& options, double area) {
  if (!std::isfinite(options.density) || options.density < 0)
    throw InvalidInputError("distance: the sample density must be a non-negative number");
  if (options.density == 0) {
    if (options.samples == 0)
      throw InvalidInputError("distance: the sample count must be positive");
    if (options.samples > kMaxDistanceSamples)
      throw InvalidInputError("distance: " + std::to_string(options.samples) +
                              " samples asked for, more than 10^9");
    return options.samples;
  }
  const double count = std::ceil(options.density * area);
  if (count > static_cast<double>(kMaxDistanceSamples))
    throw InvalidInputError("distance: a density of " + std::to_string(options.density) +
                            " asks for more than 10^9 samples on a surface of area " +
                            std::to_string(area));
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(count));
}

OneSidedDistance measure(const Mesh& from, const TriangleBvh& to, const DistanceOptions& options) {
  const SurfaceSampler sampler(from);
  if (!(sampler.area() > 0)) throw InvalidInputError("distance: a mesh has no area to sample");
  OneSidedDistance result;
  result.samples = sample_count(options, sampler.area());
  shape_detail::SplitMix64 random(options.seed);
  const unsigned threads = detail::thread_count(options.threads);
  // Chunks bound the memory; sums run in sample order, so any thread count gives the same bits.
  constexpr std::uint64_t kChunk = 1u << 16;
  std::vector<Vec3> points;
  std::vector<double> squared(kChunk);
  double sum = 0, sum_squares = 0, max_squared = 0;
  for (std::uint64_t done = 0; done < result.samples; done += kChunk) {
    const std::size_t n = static_cast<std::size_t>(std::min(kChunk, result.samples - done));
    points.resize(n);
    for (Vec3& p : points) p = sampler.sample(random);
    detail::parallel_for(n, threads, [&](std::size_t i) {
      squared[i] = to.closest_point(points[i]).squared_distance;
    });
    for (std::size_t i = 0; i < n; ++i) {
      sum += std::sqrt(squared[i]);
      sum_squares += squared[i];
      max_squared = std::max(max_squared, squared[i]);
    }
  }
  std::vector<char> used(from.positions.size(), 0);
  for (const Triangle& t : from.triangles)
    for (const std::uint32_t v : t) used[v] = 1;
  std::vector<double> vertex_squared(from.positions.size(), 0);
  detail::parallel_for(from.positions.size(), threads, [&](std::size_t v) {
    if (used[v]) vertex_squared[v] = to.closest_point(from.positions[v]).squared_distance;
  });
  for (const double d2 : vertex_squared) max_squared = std::max(max_squared, d2);
  const auto count = static_cast<double>(result.samples);
  result.mean = sum / count;
  result.rms = std::sqrt(sum_squares / count);
  result.max = std::sqrt(max_squared);
  return result;
}

}  // namespace

OneSidedDistance one_sided_distance(const Mesh& from, const Mesh& to,
                                    const DistanceOptions& options) {
  check_geometric_range(from);
  check_geometric_range(to);
  return measure(from, TriangleBvh(to), options);
}

MeshDistance mesh_distance(const Mesh& a, const Mesh& b, const DistanceOptions& options) {
  check_geometric_range(a);
  check_geometric_range(b);
  MeshDistance result;
  result.a_to_b = measure(a, TriangleBvh(b), options);
  result.b_to_a = measure(b, TriangleBvh(a), options);
  result.mean = std::max(result.a_to_b.mean, result.b_to_a.mean);
  result.rms = std::max(result.a_to_b.rms, result.b_to_a.rms);
  result.hausdorff = std::max(result.a_to_b.max, result.b_to_a.max);
  Box box;
  for (const Mesh* mesh : {&a, &b})
    for (const Triangle& t : mesh->triangles)
      for (const std::uint32_t v : t) box.add(mesh->positions[v]);
  result.diagonal = std::sqrt(squared_distance(box.low, box.high));
  return result;
}

}  // namespace primseg
