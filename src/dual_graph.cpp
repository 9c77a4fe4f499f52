#include "primseg/dual_graph.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <span>
#include <tuple>
#include <utility>

#include "face_triangles.hpp"
#include "huge_pages.hpp"
#include "no_index.hpp"
#include "parallel.hpp"

namespace primseg {
namespace {

using detail::kNone;

// Side c of a triangle runs from its corner c to corner c + 1 (mod 3).
std::uint32_t side_end(const Triangle& tri, unsigned c) {
  return tri[c == 2 ? 0 : c + 1];
}

// Which corner of a triangle comes first in every sum over its corners: the one whose position
// is lexicographically smallest (the lowest index among equal positions). The others follow in
// their cyclic order, so the orientation is kept. A file that lists a triangle from another
// corner thus gives the same statistics, costs and tree, bit for bit (round-off would otherwise
// settle the ties of symmetric parts differently).
unsigned canonical_first_corner(const Triangle& tri, std::span<const Eigen::Vector3d> positions) {
  auto before = [&](std::uint32_t a, std::uint32_t b) {
    const Eigen::Vector3d& p = positions[a];
    const Eigen::Vector3d& q = positions[b];
    return std::tie(p.x(), p.y(), p.z(), a) < std::tie(q.x(), q.y(), q.z(), b);
  };
  unsigned first = before(tri[1], tri[0]) ? 1 : 0;
  if (before(tri[2], tri[first])) first = 2;
  return first;
}

// A triangle's code in DualGraph (bit 0: flipped; bits 1 and 2: its first corner) and what it
// says.
constexpr std::uint8_t kFlippedBit = 1;
std::uint8_t with_first_corner(std::uint8_t code, unsigned first) {
  return static_cast<std::uint8_t>(code | first << 1);
}
bool is_flipped(std::uint8_t code) {
  return (code & kFlippedBit) != 0;
}
Triangle coded_corners(const Triangle& tri, std::uint8_t code) {
  // By table rather than by tests on the first corner, which branch at random.
  static constexpr std::array<std::array<std::uint8_t, 3>, 4> kFrom = {
      {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 1, 2}}};
  const std::array<std::uint8_t, 3>& from = kFrom[code >> 1 & 3];
  return {tri[from[0]], tri[from[1]], tri[from[2]]};
}

// Sorts [begin, end) stably: by insertion when tiny (as nearly all ranges are here).
template <typename Iterator, typename Less>
void stable_sort_small(Iterator begin, Iterator end, Less less) {
  if (end - begin > 32) {
    std::stable_sort(begin, end, less);
    return;
  }
  for (Iterator i = begin; i != end; ++i) {
    auto value = std::move(*i);
    Iterator hole = i;
    for (; hole != begin && less(value, *std::prev(hole)); --hole)
      *hole = std::move(*std::prev(hole));
    *hole = std::move(value);
  }
}

// A side of a triangle (joining two distinct vertices) filed under the lower vertex of its edge.
struct Side {
  std::uint32_t high;  // the edge's higher vertex
  std::uint32_t triangle;
  std::uint8_t corner;  // the side runs from this corner of the triangle
  bool forward;         // from the lower vertex to the higher
};

// The sides bucketed by the lower vertex of their edge, each bucket sorted by (high, triangle):
// the order of a comparison sort of all sides by (low, high, triangle). (A triangle with two sides
// on one edge is degenerate; which of the two comes first does not matter.)
struct SideBuckets {
  std::vector<std::size_t> offsets;  // bucket v is sides[offsets[v], offsets[v + 1])
  std::vector<Side> sides;
};

SideBuckets bucket_sides(const Mesh& mesh) {
  // Vertex ids are dense: two stable counting sorts, by the higher vertex then by the lower, sort
  // in linear time. Their writes land anywhere (vertices need not be numbered near their
  // triangles), so their addresses are fetched a few sides ahead, and the cursors that give the
  // addresses before that (those of every vertex of the triangle: the cheapest superset).
  constexpr std::size_t kAhead = 8;
  const std::size_t vertex_count = mesh.vertex_count();
  std::vector<std::size_t> high_cursor, low_cursor;
  detail::resize_huge(high_cursor, vertex_count + 1);
  detail::resize_huge(low_cursor, vertex_count + 1);
  for (const Triangle& tri : mesh.triangles)
    for (unsigned c = 0; c < 3; ++c) {
      const std::uint32_t from = tri[c], to = side_end(tri, c);
      if (from == to) continue;
      ++high_cursor[std::max(from, to)];
      ++low_cursor[std::min(from, to)];
    }
  // Exclusive prefix sums: bucket starts, the last entry the total.
  auto starts = [](std::vector<std::size_t>& counts) {
    std::size_t total = 0;
    for (std::size_t& count : counts) total += std::exchange(count, total);
  };
  starts(high_cursor);
  starts(low_cursor);
  SideBuckets buckets;
  buckets.offsets = low_cursor;
  const std::vector<std::size_t> high_offsets = high_cursor;

  // `high` of these holds the lower vertex.
  std::vector<Side> by_high;
  detail::resize_huge(by_high, high_offsets.back());
  const std::uint32_t triangle_count = mesh.triangle_count();
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    if (t + 2 * kAhead < triangle_count)
      for (std::uint32_t v : mesh.triangles[t + 2 * kAhead]) __builtin_prefetch(&high_cursor[v]);
    if (t + kAhead < triangle_count)
      for (std::uint32_t v : mesh.triangles[t + kAhead])
        __builtin_prefetch(by_high.data() + high_cursor[v]);
    const Triangle& tri = mesh.triangles[t];
    for (unsigned c = 0; c < 3; ++c) {
      const std::uint32_t from = tri[c], to = side_end(tri, c);
      if (from != to)
        by_high[high_cursor[std::max(from, to)]++] = {std::min(from, to), t,
                                                      static_cast<std::uint8_t>(c), from < to};
    }
  }
  std::vector<std::size_t>().swap(high_cursor);

  detail::resize_huge(buckets.sides, by_high.size());
  for (std::uint32_t high = 0; high < vertex_count; ++high)
    for (std::size_t s = high_offsets[high]; s < high_offsets[high + 1]; ++s) {
      if (s + 2 * kAhead < by_high.size())
        __builtin_prefetch(&low_cursor[by_high[s + 2 * kAhead].high]);
      if (s + kAhead < by_high.size())
        __builtin_prefetch(buckets.sides.data() + low_cursor[by_high[s + kAhead].high]);
      const Side& side = by_high[s];
      buckets.sides[low_cursor[side.high]++] = {high, side.triangle, side.corner, side.forward};
    }
  return buckets;
}

// What lies across the sides of each triangle: up to three slots, in increasing order of their
// edge (as mesh edges sorted by (low, high)), each a side of the triangle and another triangle.
// Across a manifold edge (two sides of distinct triangles) each names the other; on any other
// edge the distinct triangles form the chain of dual_graph.hpp, each naming the next (the last
// names none). So a slot naming a higher triangle is a dual link, and a slot naming a lower one
// a manifold edge seen from above. Slots and flags share one record so that building them
// touches one cache line per triangle.
struct TriangleSlots {
  std::array<std::uint32_t, 3> other;
  // Bits 0-1: number of slots. Slot k at bits 4k + 2 to 4k + 5: its side (2 bits), whether its
  // edge is manifold, and then whether the two triangles traverse it in the same direction (one
  // must flip). Bit 14: the triangle has a side on a boundary or non-manifold edge.
  std::uint16_t bits;

  unsigned count() const { return bits & 3u; }
  unsigned side(unsigned k) const { return (bits >> (4 * k + 2)) & 3u; }
  bool manifold(unsigned k) const { return (bits >> (4 * k + 4)) & 1u; }
  bool same_direction(unsigned k) const { return (bits >> (4 * k + 5)) & 1u; }
  bool open() const { return (bits >> 14) & 1u; }

  void add(std::uint32_t triangle, unsigned side, bool manifold, bool same_direction) {
    const unsigned k = count();
    other[k] = triangle;
    bits = static_cast<std::uint16_t>(
        bits + 1 +
        ((side | unsigned{manifold} << 2 | unsigned{same_direction} << 3) << (4 * k + 2)));
  }
  void set_open() { bits |= 1u << 14; }
};

struct Links {
  std::vector<TriangleSlots> slots;  // by triangle
  // Per range of triangles (chunk_begin of link_triangles): the links from its triangles, and
  // those of them inside an input face.
  std::vector<std::size_t> count, internal;
};

Links link_triangles(const Mesh& mesh, const SideBuckets& buckets,
                     const std::vector<std::uint32_t>& chunk_begin) {
  Links links;
  std::vector<TriangleSlots>& slots = links.slots;
  detail::resize_huge(slots, mesh.triangle_count());
  links.count.assign(chunk_begin.size() - 1, 0);
  links.internal.assign(chunk_begin.size() - 1, 0);
  const bool polygons = mesh.face_count() != mesh.triangle_count();
  auto count = [&](std::uint32_t a, std::uint32_t b) {
    const auto chunk = static_cast<std::size_t>(
        std::upper_bound(chunk_begin.begin() + 1, chunk_begin.end() - 1, a) -
        (chunk_begin.begin() + 1));
    ++links.count[chunk];
    if (polygons && mesh.face_of_triangle[a] == mesh.face_of_triangle[b]) ++links.internal[chunk];
  };
  const std::vector<Side>& sides = buckets.sides;
  for (std::size_t low = 0; low + 1 < buckets.offsets.size(); ++low) {
    const std::size_t bucket_end = buckets.offsets[low + 1];
    for (std::size_t begin = buckets.offsets[low]; begin < bucket_end;) {
      // The triangles' slots are anywhere: fetched a few sides ahead.
      if (begin + 8 < sides.size()) __builtin_prefetch(&slots[sides[begin + 8].triangle]);
      std::size_t end = begin + 1;
      while (end < bucket_end && sides[end].high == sides[begin].high) ++end;
      const Side& a = sides[begin];
      if (end - begin == 2 && a.triangle != sides[begin + 1].triangle) {
        const Side& b = sides[begin + 1];
        // Consistent neighbours traverse their shared edge in opposite directions.
        const bool same = a.forward == b.forward;
        slots[a.triangle].add(b.triangle, a.corner, true, same);
        slots[b.triangle].add(a.triangle, b.corner, true, same);
        count(a.triangle, b.triangle);
      } else {
        for (std::size_t s = begin; s < end; ++s) {
          slots[sides[s].triangle].set_open();
          if (s + 1 < end && sides[s].triangle != sides[s + 1].triangle) {
            slots[sides[s].triangle].add(sides[s + 1].triangle, sides[s].corner, false, false);
            count(sides[s].triangle, sides[s + 1].triangle);
          }
        }
      }
      begin = end;
    }
  }
  return links;
}

// The normal of a triangle given by its canonical corners, of length twice its area, negated when
// `flipped`.
inline Eigen::Vector3d oriented_normal(const Triangle& corners,
                                       std::span<const Eigen::Vector3d> positions, bool flipped) {
  const Eigen::Vector3d n = (positions[corners[1]] - positions[corners[0]])
                                .cross(positions[corners[2]] - positions[corners[0]]);
  return flipped ? Eigen::Vector3d(-n) : n;
}

// Triangle t's normal, oriented (negated where the orientation was flipped), of length twice its
// area.
inline Eigen::Vector3d oriented_normal(std::span<const Triangle> triangles,
                                       std::span<const Eigen::Vector3d> positions,
                                       std::span<const std::uint8_t> codes, std::uint32_t t) {
  return oriented_normal(coded_corners(triangles[t], codes[t]), positions, is_flipped(codes[t]));
}

// The dual edges of ranges of faces, each face's links in the order (other face, edge, lower
// triangle): the edges come sorted by face pair, and the links of one pair add in increasing edge
// order, as they would after a stable sort of all links in edge order.
class FaceLinks {
 public:
  FaceLinks(const Mesh& mesh, std::span<const Eigen::Vector3d> positions,
            std::span<const std::uint8_t> codes, std::span<const std::uint32_t> first_triangle,
            std::span<const TriangleSlots> neighbours)
      : triangles_(mesh.triangles),
        face_of_triangle_(mesh.face_of_triangle),
        positions_(positions),
        codes_(codes),
        first_triangle_(first_triangle),
        neighbours_(neighbours),
        polygons_(mesh.face_count() != mesh.triangle_count()) {}

  /// Appends the dual edges of faces [face_begin, face_end) to `edges`, the links inside them
  /// to `internal`.
  void add(std::uint32_t face_begin, std::uint32_t face_end, std::vector<DualEdge>& edges,
           std::vector<std::pair<std::uint32_t, EdgeStats>>& internal) const {
    // In blocks, so that the random reads of a block can be issued before they are needed.
    constexpr std::size_t kBlock = 256;
    std::vector<Link> block;
    block.reserve(kBlock);
    for (std::uint32_t f = face_begin; f < face_end; ++f) {
      const std::size_t face_links = block.size();
      for (std::uint32_t t = first_triangle_[f]; t < first_triangle_[f + 1]; ++t) {
        const TriangleSlots& slots = neighbours_[t];
        const Triangle& tri = triangles_[t];
        for (std::uint32_t v : tri) __builtin_prefetch(&positions_[v]);
        for (unsigned k = 0; k < slots.count(); ++k) {
          const std::uint32_t other = slots.other[k];
          if (other < t) continue;  // a manifold edge seen from above
          __builtin_prefetch(&triangles_[other]);
          __builtin_prefetch(&codes_[other]);
          const std::uint32_t from = tri[slots.side(k)], to = side_end(tri, slots.side(k));
          block.push_back({f, polygons_ ? face_of_triangle_[other] : other, std::min(from, to),
                           std::max(from, to), t, other});
        }
      }
      if (block.size() - face_links > 1)
        stable_sort_small(block.begin() + static_cast<std::ptrdiff_t>(face_links), block.end(),
                          [](const Link& a, const Link& b) {
                            return std::tie(a.other_face, a.low, a.high, a.first) <
                                   std::tie(b.other_face, b.low, b.high, b.first);
                          });
      if (block.size() >= kBlock) add_block(block, edges, internal);
    }
    add_block(block, edges, internal);
  }

 private:
  struct Link {
    std::uint32_t face, other_face;  // of the lower and the higher triangle
    std::uint32_t low, high;         // the shared edge
    std::uint32_t first, second;     // triangles, first < second
    std::uint32_t opposite = kNone;  // the vertex of the second off the edge
    bool angled = false;             // both normals nonzero, and a vertex off the edge
    bool concave = false;
    double y = 0, x = 0;  // the signed dihedral angle is ±atan2(y, x), − if concave
  };

  Eigen::Vector3d oriented_normal(std::uint32_t t) const {
    return primseg::oriented_normal(triangles_, positions_, codes_, t);
  }

  void add_block(std::vector<Link>& block, std::vector<DualEdge>& edges,
                 std::vector<std::pair<std::uint32_t, EdgeStats>>& internal) const {
    std::uint32_t normal_of = kNone;
    Eigen::Vector3d n1 = Eigen::Vector3d::Zero();
    bool n1_nonzero = false;
    // The random reads first, in a loop short enough for many of them to be in flight at once.
    for (Link& link : block) {
      for (std::uint32_t v : triangles_[link.second])
        if (v != link.low && v != link.high) link.opposite = v;
      if (link.opposite != kNone) __builtin_prefetch(&positions_[link.opposite]);
    }
    for (Link& link : block) {
      if (link.first != normal_of) {
        normal_of = link.first;
        n1 = oriented_normal(link.first);
        n1_nonzero = n1.squaredNorm() > 0;
      }
      if (link.opposite == kNone || !n1_nonzero) continue;
      const Eigen::Vector3d n2 = oriented_normal(link.second);
      if (!(n2.squaredNorm() > 0)) continue;
      link.angled = true;
      link.y = n1.cross(n2).norm();
      link.x = n1.dot(n2);
      // From the edge's midpoint rather than an end: which end has the lower index must not
      // decide a nearly flat edge's sign (round-off), or renumbered vertices would change trees.
      const Eigen::Vector3d midpoint = (positions_[link.low] + positions_[link.high]) / 2;
      link.concave = (positions_[link.opposite] - midpoint).dot(n1) > 0;
    }
    for (const Link& link : block) {
      double beta = 0;
      // atan2 keeps full precision near 0 where acos of the dot product would not.
      if (link.angled) beta = std::atan2(link.y, link.x);
      if (link.concave) beta = -beta;
      const Eigen::Vector3d edge = positions_[link.high] - positions_[link.low];
      if (link.other_face == link.face) {
        internal.push_back({link.face, {}});
        internal.back().second.add_edge(edge, beta);
      } else if (!edges.empty() && edges.back().first == link.face &&
                 edges.back().second == link.other_face) {
        EdgeStats stats;
        stats.add_edge(edge, beta);
        edges.back().shared += stats;
      } else {
        edges.push_back({link.face, link.other_face, {}});
        edges.back().shared.add_edge(edge, beta);
      }
    }
    block.clear();
  }

  // Spans rather than references to vectors: one indirection less on every access.
  std::span<const Triangle> triangles_;
  std::span<const std::uint32_t> face_of_triangle_;
  std::span<const Eigen::Vector3d> positions_;
  std::span<const std::uint8_t> codes_;
  std::span<const std::uint32_t> first_triangle_;
  std::span<const TriangleSlots> neighbours_;
  bool polygons_;
};

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }
  /// The set of each element, the sets numbered by their lowest element; `count` is set to the
  /// number of sets. Consumes the structure: the labels overwrite the parents.
  std::vector<std::uint32_t> labels(std::uint32_t& count) && {
    // Every parent is lower than its child, hence labelled before it, with the label of the set.
    count = 0;
    for (std::uint32_t x = 0; x < parent_.size(); ++x)
      parent_[x] = parent_[x] == x ? count++ : parent_[parent_[x]];
    return std::move(parent_);
  }

 private:
  std::vector<std::uint32_t> parent_;
};

}  // namespace

double WorkingFrame::scale() const {
  return std::ldexp(1.0, exponent);
}

Eigen::Vector3d WorkingFrame::to_working(const Vec3& x) const {
  return {std::ldexp(x[0] - center.x(), -exponent), std::ldexp(x[1] - center.y(), -exponent),
          std::ldexp(x[2] - center.z(), -exponent)};
}

Vec3 WorkingFrame::to_input(const Eigen::Vector3d& x) const {
  return {std::ldexp(x.x(), exponent) + center.x(), std::ldexp(x.y(), exponent) + center.y(),
          std::ldexp(x.z(), exponent) + center.z()};
}

Primitive WorkingFrame::to_input(const Primitive& working) const {
  Primitive p = working;
  p.point = to_input(Eigen::Vector3d(working.point[0], working.point[1], working.point[2]));
  p.radius = std::ldexp(working.radius, exponent);
  p.minor_radius = std::ldexp(working.minor_radius, exponent);
  return p;
}

namespace {

WorkingFrame frame_of_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  WorkingFrame frame;
  // Halving each bound before adding cannot overflow and stays exact for normal numbers.
  frame.center = lo * 0.5 + hi * 0.5;
  const double extent = (hi - frame.center).cwiseMax(frame.center - lo).maxCoeff();
  if (extent > 0) std::frexp(extent, &frame.exponent);
  return frame;
}

// working_frame_for(mesh), given the valences: the used vertices in index order rather than
// corner by corner, which reads the positions once and in order. The bounds are the same unless
// a bound is zero and both signed zeros occur on its axis: then the first in corner order is the
// bound.
WorkingFrame working_frame_of_used(const Mesh& mesh, const std::vector<std::uint32_t>& valence) {
  if (mesh.triangles.empty()) return {};
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  std::array<unsigned, 3> zero_signs{};  // bit 0: +0 seen, bit 1: -0 seen
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    if (valence[v] == 0) continue;
    for (int a = 0; a < 3; ++a) {
      const double x = mesh.positions[v][a];
      lo[a] = std::min(lo[a], x);
      hi[a] = std::max(hi[a], x);
      if (x == 0) zero_signs[a] |= std::signbit(x) ? 2u : 1u;
    }
  }
  for (int a = 0; a < 3; ++a)
    if ((lo[a] == 0 || hi[a] == 0) && zero_signs[a] == 3) return working_frame_for(mesh);
  return frame_of_box(lo, hi);
}

}  // namespace

WorkingFrame working_frame_for(const Mesh& mesh) {
  if (mesh.triangles.empty()) return {};
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Triangle& t : mesh.triangles)
    for (std::uint32_t v : t)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], mesh.positions[v][a]);
        hi[a] = std::max(hi[a], mesh.positions[v][a]);
      }
  return frame_of_box(lo, hi);
}

namespace {

// The mesh's positions in the working frame.
std::vector<Eigen::Vector3d> working_positions(const Mesh& mesh, const WorkingFrame& frame) {
  std::vector<Eigen::Vector3d> positions;
  detail::resize_huge(positions, mesh.positions.size());
  // A product by a power of two rounds once, as ldexp does, when the power is a double.
  const double scale = std::ldexp(1.0, -frame.exponent);
  if (scale > 0 && std::isfinite(scale)) {
    for (std::size_t v = 0; v < positions.size(); ++v)
      for (int a = 0; a < 3; ++a)
        positions[v][a] = (mesh.positions[v][a] - frame.center[a]) * scale;
  } else {
    for (std::size_t v = 0; v < positions.size(); ++v)
      positions[v] = frame.to_working(mesh.positions[v]);
  }
  return positions;
}

// The triangles' orientation, before closed components are turned outward: each triangle's code
// (bit 0 only, flipped, until turn_outward() adds the first corner), each triangle's orientation
// component (numbered by its lowest triangle) and whether each component is open (a boundary, or
// not orientable: no inside).
struct Orientation {
  std::vector<std::uint8_t> codes;
  std::vector<std::uint32_t> component;
  std::vector<std::uint8_t> open;
};

// Breadth-first over manifold edges from the lowest unvisited triangle, the edges of a triangle
// in increasing order (on a non-orientable component the order decides the flips).
Orientation orient(const std::vector<TriangleSlots>& neighbours) {
  const auto triangle_count = static_cast<std::uint32_t>(neighbours.size());
  Orientation o;
  detail::resize_huge(o.codes, triangle_count);
  detail::resize_huge(o.component, triangle_count);
  std::fill(o.component.begin(), o.component.end(), kNone);
  std::vector<std::uint32_t> queue;  // every triangle enters it once
  detail::resize_huge(queue, triangle_count);
  std::size_t queued = 0;
  for (std::uint32_t seed = 0; seed < triangle_count; ++seed) {
    if (o.component[seed] != kNone) continue;
    const auto component = static_cast<std::uint32_t>(o.open.size());
    o.open.push_back(0);
    o.component[seed] = component;
    queue[queued++] = seed;
    for (std::size_t head = queued - 1; head < queued; ++head) {
      if (head + 4 < queued) {
        const TriangleSlots& ahead = neighbours[queue[head + 4]];
        for (unsigned k = 0; k < ahead.count(); ++k) {
          __builtin_prefetch(&o.component[ahead.other[k]]);
          __builtin_prefetch(&o.codes[ahead.other[k]]);
        }
      }
      if (head + 8 < queued) __builtin_prefetch(&neighbours[queue[head + 8]]);
      const std::uint32_t t = queue[head];
      const TriangleSlots& slots = neighbours[t];
      if (slots.open()) o.open[component] = 1;
      for (unsigned k = 0; k < slots.count(); ++k) {
        if (!slots.manifold(k)) continue;
        const std::uint32_t other = slots.other[k];
        const std::uint8_t wanted = o.codes[t] ^ std::uint8_t{slots.same_direction(k)};
        if (o.component[other] == kNone) {
          o.component[other] = component;
          o.codes[other] = wanted;
          queue[queued++] = other;
        } else if (o.codes[other] != wanted) {
          o.open[component] = 1;  // not orientable (a Möbius band): no inside
        }
      }
    }
  }
  return o;
}

// Closed components face outward: flips those of negative signed volume in `orientation`, whose
// codes also get each triangle's first corner.
// Returns each face's connected component of the dual graph and sets `count`: the components of
// the orientation joined across the other links and within polygon faces; numbered by their
// lowest member, as the orientation components are by their lowest triangle, they are numbered
// by their lowest face.
std::vector<std::uint32_t> turn_outward(const Mesh& mesh,
                                        const std::vector<Eigen::Vector3d>& positions,
                                        const std::vector<TriangleSlots>& neighbours,
                                        const std::vector<std::uint32_t>& first_triangle,
                                        Orientation& orientation, std::uint32_t& count) {
  const std::uint32_t triangle_count = mesh.triangle_count();
  const std::uint32_t face_count = mesh.face_count();
  std::vector<double> volume(orientation.open.size(), 0.0);
  UnionFind joined(orientation.open.size());
  const bool polygons = face_count != triangle_count;
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    if (t + 16 < triangle_count)
      for (std::uint32_t u : mesh.triangles[t + 16]) __builtin_prefetch(&positions[u]);
    std::uint8_t& code = orientation.codes[t];
    code = with_first_corner(code, canonical_first_corner(mesh.triangles[t], positions));
    const Triangle tri = coded_corners(mesh.triangles[t], code);
    const double v = positions[tri[0]].dot(positions[tri[1]].cross(positions[tri[2]]));
    volume[orientation.component[t]] += is_flipped(code) ? -v : v;
    const TriangleSlots& slots = neighbours[t];
    for (unsigned k = 0; k < slots.count(); ++k)
      if (!slots.manifold(k))
        joined.unite(orientation.component[t], orientation.component[slots.other[k]]);
    if (polygons && t > 0 && mesh.face_of_triangle[t] == mesh.face_of_triangle[t - 1])
      joined.unite(orientation.component[t], orientation.component[t - 1]);
  }
  for (std::uint32_t t = 0; t < triangle_count; ++t) {
    const std::uint32_t c = orientation.component[t];
    if (!orientation.open[c] && volume[c] < 0) orientation.codes[t] ^= kFlippedBit;
  }
  const std::vector<std::uint32_t> label = std::move(joined).labels(count);
  std::vector<std::uint32_t> component_of_face(face_count);
  for (std::uint32_t f = 0; f < face_count; ++f)
    component_of_face[f] = label[orientation.component[first_triangle[f]]];
  return component_of_face;
}

}  // namespace

DualGraph::DualGraph(const Mesh& mesh, VertexWeights weights, unsigned threads)
    : mesh_(&mesh), weights_(weights) {
  threads = detail::thread_count(threads);
  const std::uint32_t face_count = mesh.face_count();

  detail::resize_huge(valence_, mesh.positions.size());
  for (const Triangle& t : mesh.triangles)
    for (std::uint32_t v : t) ++valence_[v];
  frame_ = working_frame_of_used(mesh, valence_);
  positions_ = working_positions(mesh, frame_);

  first_triangle_ = detail::first_triangles(mesh);

  // Ranges of faces for threads (see below), and the triangles they start at.
  const std::size_t chunk_count = std::min<std::size_t>(threads, face_count / 16384 + 1);
  auto chunk_face = [&](std::size_t chunk) {
    return static_cast<std::uint32_t>(face_count * chunk / chunk_count);
  };
  std::vector<std::uint32_t> chunk_begin(chunk_count + 1);
  for (std::size_t chunk = 0; chunk <= chunk_count; ++chunk)
    chunk_begin[chunk] = first_triangle_[chunk_face(chunk)];
  Links links = link_triangles(mesh, bucket_sides(mesh), chunk_begin);
  const std::vector<TriangleSlots>& neighbours = links.slots;
  {
    Orientation orientation = orient(neighbours);
    component_of_face_ =
        turn_outward(mesh, positions_, neighbours, first_triangle_, orientation, component_count_);
    triangle_codes_ = std::move(orientation.codes);
  }

  // The dual edges: faces are independent, so ranges of them go to threads, their results
  // concatenated in order.
  const std::size_t external =
      std::accumulate(links.count.begin(), links.count.end(), std::size_t{0}) -
      std::accumulate(links.internal.begin(), links.internal.end(), std::size_t{0});
  detail::reserve_huge_to_fill(edges_, external);
  detail::reserve_huge_to_fill(
      internal_edges_,
      std::accumulate(links.internal.begin(), links.internal.end(), std::size_t{0}));
  const FaceLinks face_links(mesh, positions_, triangle_codes_, first_triangle_, neighbours);
  std::vector<std::vector<DualEdge>> later_edges(chunk_count - 1);
  std::vector<std::vector<std::pair<std::uint32_t, EdgeStats>>> later_internal(chunk_count - 1);
  detail::parallel_for_threads(
      chunk_count, static_cast<unsigned>(chunk_count), [&](std::size_t chunk, unsigned) {
        std::vector<DualEdge>& edges = chunk == 0 ? edges_ : later_edges[chunk - 1];
        std::vector<std::pair<std::uint32_t, EdgeStats>>& internal =
            chunk == 0 ? internal_edges_ : later_internal[chunk - 1];
        if (chunk > 0) {
          detail::reserve_huge_to_fill(edges, links.count[chunk] - links.internal[chunk]);
          detail::reserve_huge_to_fill(internal, links.internal[chunk]);
        }
        face_links.add(chunk_face(chunk), chunk_face(chunk + 1), edges, internal);
      });
  std::vector<TriangleSlots>().swap(links.slots);
  for (std::size_t chunk = 0; chunk + 1 < chunk_count; ++chunk) {
    edges_.insert(edges_.end(), later_edges[chunk].begin(), later_edges[chunk].end());
    std::vector<DualEdge>().swap(later_edges[chunk]);
    internal_edges_.insert(internal_edges_.end(), later_internal[chunk].begin(),
                           later_internal[chunk].end());
    std::vector<std::pair<std::uint32_t, EdgeStats>>().swap(later_internal[chunk]);
  }
}

Triangle DualGraph::corners(std::uint32_t t) const {
  return coded_corners(triangles()[t], triangle_codes_[t]);
}

double DualGraph::triangle_area(std::uint32_t t) const {
  return area_of(corners(t));
}

inline double DualGraph::area_of(const Triangle& corners) const {
  return 0.5 * oriented_normal(corners, positions_, false).norm();
}

void DualGraph::prefetch_face(std::uint32_t f) const {
  __builtin_prefetch(&first_triangle_[f]);
  // Most faces are one triangle, and face f's is then triangle f when all are.
  const std::span<const Triangle> all = triangles();
  if (first_triangle_.size() == all.size() + 1) __builtin_prefetch(&all[f]);
}

void DualGraph::prefetch_face_corners(std::uint32_t f) const {
  for (std::uint32_t t = first_triangle_[f]; t < first_triangle_[f + 1]; ++t)
    for (std::uint32_t v : triangles()[t]) __builtin_prefetch(&positions_[v]);
}

std::array<double, 3> DualGraph::corner_weights(std::uint32_t t) const {
  const Triangle tri = corners(t);
  return corner_weights_of(tri, weights_ == VertexWeights::Area ? area_of(tri) : 0.0);
}

inline std::array<double, 3> DualGraph::corner_weights_of(const Triangle& corners,
                                                          double area) const {
  if (weights_ == VertexWeights::Uniform)
    return {1.0 / valence_[corners[0]], 1.0 / valence_[corners[1]], 1.0 / valence_[corners[2]]};
  return {area / 3, area / 3, area / 3};
}

inline Eigen::Vector3d DualGraph::centroid_of(const Triangle& corners) const {
  return (positions_[corners[0]] + positions_[corners[1]] + positions_[corners[2]]) / 3;
}

inline Eigen::Vector3d DualGraph::face_origin(std::uint32_t f, const Eigen::Vector3d& weighted_sum,
                                              double weight) const {
  if (weight > 0) return weighted_sum / weight;
  return centroid_of(corners(first_triangle_[f]));
}

inline EdgeStats DualGraph::internal_edges_of(std::uint32_t f) const {
  EdgeStats edges;
  if (first_triangle_[f + 1] - first_triangle_[f] <= 1) return edges;  // none inside a triangle
  auto it =
      std::lower_bound(internal_edges_.begin(), internal_edges_.end(), f,
                       [](const auto& entry, std::uint32_t face) { return entry.first < face; });
  for (; it != internal_edges_.end() && it->first == f; ++it) edges += it->second;
  return edges;
}

bool DualGraph::face_corners(std::uint32_t f, FaceCorners& corners) const {
  const std::uint32_t begin = first_triangle_[f], count = first_triangle_[f + 1] - begin;
  if (count > FaceCorners::kMaxTriangles) return false;
  // As face_stats(): area vectors and weights first, then everything about the weighted centroid.
  const auto read = [&](std::uint32_t triangle_count) __attribute__((always_inline)) {
    Eigen::Vector3d weighted_sum = Eigen::Vector3d::Zero();
    double weight = 0;
    corners.triangle_count = triangle_count;
    std::array<Triangle, FaceCorners::kMaxTriangles> triangles;
    for (std::uint32_t i = 0; i < triangle_count; ++i) {
      const Triangle& tri = triangles[i] = this->corners(begin + i);
      const Eigen::Vector3d normal =
          oriented_normal(tri, positions_, is_flipped(triangle_codes_[begin + i]));
      corners.areas[i] = 0.5 * normal.norm();
      corners.area_normals[i] = 0.5 * normal;
      const std::array<double, 3> w = corner_weights_of(tri, corners.areas[i]);
      for (int k = 0; k < 3; ++k) {
        corners.weights[3 * i + k] = w[k];
        weighted_sum += w[k] * positions_[tri[k]];
        weight += w[k];
      }
    }
    corners.centroid = face_origin(f, weighted_sum, weight);
    corners.weight = weight;
    corners.second_moment.setZero();
    corners.normal_sum.setZero();
    corners.normal_position.setZero();
    corners.area = 0;
    for (std::uint32_t i = 0; i < triangle_count; ++i) {
      const Triangle& tri = triangles[i];
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d y = positions_[tri[k]] - corners.centroid;
        corners.offsets[3 * i + k] = y;
        corners.second_moment.noalias() += (corners.weights[3 * i + k] * y) * y.transpose();
      }
      corners.triangle_offsets[i] = centroid_of(tri) - corners.centroid;
      corners.normal_position += corners.triangle_offsets[i] * corners.area_normals[i].transpose();
      corners.normal_sum += corners.area_normals[i];
      corners.area += corners.areas[i];
    }
    corners.edges = internal_edges_of(f);
  };
  // A face of one triangle (nearly every face) by a call with a constant count, which the
  // compiler unrolls (forced inline, else it is not): a sixth fewer instructions, the same
  // operations in the same order.
  if (count == 1)
    read(1);
  else
    read(count);
  return true;
}

ClusterStats DualGraph::face_stats(std::uint32_t f, bool with_samples, int max_degree) const {
  ClusterStats stats;
  face_stats(f, stats, with_samples, max_degree);
  return stats;
}

void DualGraph::face_stats(std::uint32_t f, ClusterStats& stats, bool with_samples,
                           int max_degree) const {
  const std::uint32_t begin = first_triangle_[f], end = first_triangle_[f + 1];
  // Area vectors and corner weights first: the moments are taken about the weighted centroid of
  // the corners (the first triangle's centroid if they weigh nothing), so that the statistics are
  // centred as the fitters and unions expect. Most faces are one triangle.
  struct Corners {
    Triangle corners;        // canonical
    Eigen::Vector3d normal;  // oriented, length twice the area
    std::array<double, 3> weights;
  };
  constexpr std::uint32_t kInline = 4;
  std::array<Corners, kInline> inline_corners;
  std::vector<Corners> many;
  Corners* corners = inline_corners.data();
  if (end - begin > kInline) {
    many.resize(end - begin);
    corners = many.data();
  }
  Eigen::Vector3d weighted_sum = Eigen::Vector3d::Zero();
  double weight = 0;
  for (std::uint32_t t = begin; t < end; ++t) {
    Corners& c = corners[t - begin];
    const Triangle& tri = c.corners = this->corners(t);
    c.normal = oriented_normal(tri, positions_, is_flipped(triangle_codes_[t]));
    c.weights = corner_weights_of(tri, 0.5 * c.normal.norm());
    for (int k = 0; k < 3; ++k) {
      weighted_sum += c.weights[k] * positions_[tri[k]];
      weight += c.weights[k];
    }
  }
  stats.moments = Moments(face_origin(f, weighted_sum, weight));
  stats.edges = internal_edges_of(f);
  stats.normal_sum.setZero();
  stats.normal_position.setZero();
  stats.face_planes = {};
  stats.area = 0;
  stats.triangle_count = 0;
  stats.samples.samples.clear();
  for (std::uint32_t t = begin; t < end; ++t) {
    const Corners& c = corners[t - begin];
    const Triangle& tri = c.corners;
    for (int k = 0; k < 3; ++k)
      stats.moments.add_point(positions_[tri[k]], c.weights[k], max_degree);
    const Eigen::Vector3d& n = c.normal;
    const Eigen::Vector3d centroid = centroid_of(tri);
    stats.normal_position += (centroid - stats.moments.origin()) * (0.5 * n).transpose();
    stats.normal_sum += 0.5 * n;
    const double area = 0.5 * n.norm();
    if (area > 0)
      stats.face_planes.add_face(n / (2 * area), area, centroid - stats.moments.origin());
    if (with_samples) {
      const Eigen::Vector3f unit =
          area > 0 ? Eigen::Vector3f((n / (2 * area)).cast<float>()) : Eigen::Vector3f::Zero();
      for (int k = 0; k < 3; ++k)
        stats.samples.add({positions_[tri[k]], unit, (centroid - positions_[tri[k]]).cast<float>(),
                           c.weights[k],
                           SampleReservoir::priority_of(std::uint64_t{t} * 3 + k, c.weights[k])});
    }
    stats.area += area;
    ++stats.triangle_count;
  }
  stats.moments.discard_first_moments();
}

namespace {

// The Morton code of a working-frame point (coordinates within [-1, 1]): 10 bits per axis,
// interleaved from x's lowest, 30 bits in all: a surface crosses millions of the billion cells,
// about one face each at 10M faces.
std::uint32_t morton_code(const Eigen::Vector3d& p) {
  auto spread = [](std::uint32_t v) {  // bit k of v to bit 3k
    v = (v | v << 16) & 0x030000ffu;
    v = (v | v << 8) & 0x0300f00fu;
    v = (v | v << 4) & 0x030c30c3u;
    v = (v | v << 2) & 0x09249249u;
    return v;
  };
  constexpr double kCells = 1023;
  std::uint32_t code = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double unit = (p[axis] + 1) * 0.5;
    const double cell = unit > 0 ? std::min(unit, 1.0) * kCells : 0.0;
    code |= spread(static_cast<std::uint32_t>(cell)) << axis;
  }
  return code;
}

// Sorts keys (a 30-bit code above a 32-bit payload) by their code, stably: a least-significant-
// digit radix sort, three passes of 10 bits.
void sort_by_code(std::vector<std::uint64_t>& keys) {
  std::vector<std::uint64_t> buffer;
  detail::resize_huge(buffer, keys.size());
  for (int shift = 32; shift < 62; shift += 10) {
    std::array<std::size_t, 1025> start{};
    for (std::uint64_t key : keys) ++start[((key >> shift) & 1023) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    for (std::uint64_t key : keys) buffer[start[(key >> shift) & 1023]++] = key;
    keys.swap(buffer);
  }
}

}  // namespace

SpatialOrder DualGraph::in_spatial_order() const {
  const std::uint32_t face_count = this->face_count();
  SpatialOrder order;
  {
    std::vector<std::uint64_t> keys;  // code above face: equal codes keep the faces' order
    detail::resize_huge(keys, face_count);
    for (std::uint32_t f = 0; f < face_count; ++f)
      keys[f] = std::uint64_t{morton_code(centroid_of(corners(first_triangle_[f])))} << 32 | f;
    sort_by_code(keys);
    detail::resize_huge(order.original_face, face_count);
    for (std::uint32_t i = 0; i < face_count; ++i)
      order.original_face[i] = static_cast<std::uint32_t>(keys[i]);
  }
  std::vector<std::uint32_t> new_face;
  detail::resize_huge(new_face, face_count);
  for (std::uint32_t i = 0; i < face_count; ++i) new_face[order.original_face[i]] = i;

  order.graph.reset(new DualGraph());
  DualGraph& graph = *order.graph;
  graph.mesh_ = mesh_;
  graph.weights_ = weights_;
  graph.frame_ = frame_;
  graph.component_count_ = component_count_;
  // Triangles face by face in the new order, each face's in its own order; vertices numbered as
  // they are first met (vertices of no triangle are dropped: nothing reads them).
  const std::size_t triangle_count = first_triangle_.back();
  detail::resize_huge(graph.first_triangle_, std::size_t{face_count} + 1);
  detail::resize_huge(graph.renumbered_triangles_, triangle_count);
  detail::resize_huge(graph.triangle_codes_, triangle_count);
  detail::resize_huge(graph.component_of_face_, face_count);
  std::vector<std::uint32_t> new_vertex;
  detail::resize_huge(new_vertex, positions_.size());
  std::fill(new_vertex.begin(), new_vertex.end(), kNone);
  detail::reserve_huge_to_fill(graph.positions_, positions_.size());
  detail::reserve_huge_to_fill(graph.valence_, valence_.size());
  std::uint32_t u = 0;
  graph.first_triangle_[0] = 0;
  for (std::uint32_t i = 0; i < face_count; ++i) {
    const std::uint32_t f = order.original_face[i];
    for (std::uint32_t t = first_triangle_[f]; t < first_triangle_[f + 1]; ++t, ++u) {
      Triangle tri = corners(t);  // in the original ids' order, which renumbering would not keep
      for (std::uint32_t& v : tri) {
        std::uint32_t& renumbered = new_vertex[v];
        if (renumbered == kNone) {
          renumbered = static_cast<std::uint32_t>(graph.positions_.size());
          graph.positions_.push_back(positions_[v]);
          graph.valence_.push_back(valence_[v]);
        }
        v = renumbered;
      }
      graph.renumbered_triangles_[u] = tri;
      graph.triangle_codes_[u] = triangle_codes_[t] & kFlippedBit;  // stored from its first corner
    }
    graph.first_triangle_[i + 1] = u;
    graph.component_of_face_[i] = component_of_face_[f];
  }

  // Dual edges by their (lower, higher) new faces: bucketed by the lower, each bucket (a face's
  // few edges to higher faces) sorted by the higher.
  const std::size_t edge_count = edges_.size();
  std::vector<std::uint64_t> edge_keys;  // lower above higher
  detail::resize_huge(edge_keys, edge_count);
  std::vector<std::uint32_t> bucket_start(std::size_t{face_count} + 1, 0);
  for (std::size_t j = 0; j < edge_count; ++j) {
    const std::uint32_t a = new_face[edges_[j].first], b = new_face[edges_[j].second];
    const std::uint32_t lower = std::min(a, b);
    edge_keys[j] = std::uint64_t{lower} << 32 | std::max(a, b);
    ++bucket_start[lower + 1];
  }
  std::partial_sum(bucket_start.begin(), bucket_start.end(), bucket_start.begin());
  detail::resize_huge(order.original_edge, edge_count);
  {
    std::vector<std::uint32_t> next(bucket_start.begin(), bucket_start.end() - 1);
    for (std::size_t j = 0; j < edge_count; ++j)
      order.original_edge[next[edge_keys[j] >> 32]++] = static_cast<std::uint32_t>(j);
  }
  for (std::uint32_t i = 0; i < face_count; ++i)
    stable_sort_small(
        order.original_edge.begin() + bucket_start[i],
        order.original_edge.begin() + bucket_start[i + 1],
        [&](std::uint32_t x, std::uint32_t y) { return edge_keys[x] < edge_keys[y]; });
  detail::resize_huge(graph.edges_, edge_count);
  for (std::size_t k = 0; k < edge_count; ++k) {
    const DualEdge& e = edges_[order.original_edge[k]];
    graph.edges_[k] = {new_face[e.first], new_face[e.second], e.shared};
  }

  // Edges inside polygon faces: by new face, each face's in their order.
  graph.internal_edges_ = internal_edges_;
  for (auto& entry : graph.internal_edges_) entry.first = new_face[entry.first];
  std::stable_sort(graph.internal_edges_.begin(), graph.internal_edges_.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  return order;
}

}  // namespace primseg
