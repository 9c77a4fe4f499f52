#include "planar_triangulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <deque>
#include <stdexcept>
#include <unordered_set>

namespace primseg::shape_detail {
namespace {

double orient(const Point2& a, const Point2& b, const Point2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

/// Positive when d lies inside the circumcircle of the counter-clockwise triangle abc.
double incircle(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  const double adx = a.x - d.x, ady = a.y - d.y;
  const double bdx = b.x - d.x, bdy = b.y - d.y;
  const double cdx = c.x - d.x, cdy = c.y - d.y;
  return (adx * adx + ady * ady) * (bdx * cdy - cdx * bdy) +
         (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy) +
         (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady);
}

double segment_distance(const Point2& p, const Point2& a, const Point2& b) {
  const double ex = b.x - a.x, ey = b.y - a.y;
  const double len2 = ex * ex + ey * ey;
  double t = len2 > 0 ? ((p.x - a.x) * ex + (p.y - a.y) * ey) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * ex), p.y - (a.y + t * ey));
}

std::uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<std::uint64_t>(std::min(a, b));
  const auto hi = static_cast<std::uint64_t>(std::max(a, b));
  return (lo << 32) | hi;
}

/// Incremental (Bowyer-Watson) Delaunay triangulation inside a large enclosing triangle, with
/// edge recovery by flips. Predicates are plain floating point with small tolerances; instead of
/// exact arithmetic, each cavity is trimmed until it is star-shaped from the new point, which
/// keeps the triangulation valid even where the input is degenerate (co-circular points on
/// sampled circles, rectangle corners).
class ConstrainedDelaunay {
 public:
  explicit ConstrainedDelaunay(std::vector<Point2> points)
      : points_(std::move(points)), real_count_(static_cast<int>(points_.size())) {
    double min_x = points_[0].x, max_x = min_x, min_y = points_[0].y, max_y = min_y;
    for (const Point2& p : points_) {
      min_x = std::min(min_x, p.x), max_x = std::max(max_x, p.x);
      min_y = std::min(min_y, p.y), max_y = std::max(max_y, p.y);
    }
    const double extent = std::max({max_x - min_x, max_y - min_y, 1e-300});
    orient_eps_ = 1e-13 * extent * extent;
    incircle_eps_ = 1e-12 * extent * extent * extent * extent;
    const double cx = 0.5 * (min_x + max_x), cy = 0.5 * (min_y + max_y), far = 50 * extent;
    points_.push_back({cx - far, cy - far});
    points_.push_back({cx + far, cy - far});
    points_.push_back({cx, cy + far});
    triangles_.push_back({{real_count_, real_count_ + 1, real_count_ + 2}, {-1, -1, -1}, true});
    for (int i = 0; i < real_count_; ++i) insert(i);
  }

  /// Makes every (a, b) an edge of the triangulation, flipping the edges that cross it, and a
  /// boundary of the domain.
  void constrain(const std::vector<std::pair<int, int>>& edges) {
    // Marking them all first protects each from the flips that recover the others.
    for (const auto& [a, b] : edges) constrained_.insert(edge_key(a, b));
    std::unordered_set<std::uint64_t> present;
    for (const Tri& tri : triangles_) {
      if (!tri.alive) continue;
      for (int i = 0; i < 3; ++i) present.insert(edge_key(tri.v[i], tri.v[(i + 1) % 3]));
    }
    for (const auto& [a, b] : edges) {
      if (present.count(edge_key(a, b))) continue;
      for (std::size_t flips = 0; !has_edge(a, b); ++flips) {
        if (flips > 4 * triangles_.size() || !flip_one_crossing_edge(a, b)) {
          throw std::logic_error("planar triangulation: cannot recover a boundary edge");
        }
      }
    }
  }

  /// Triangles inside the domain: separated from the enclosing triangle by an odd number of
  /// constrained edges.
  std::vector<std::array<std::uint32_t, 3>> inside_triangles() const {
    std::vector<int> depth(triangles_.size(), -1);
    std::deque<int> queue;
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      if (triangles_[t].alive && touches_enclosing(triangles_[t])) {
        depth[t] = 0;
        queue.push_back(static_cast<int>(t));
      }
    }
    while (!queue.empty()) {
      const int t = queue.front();
      queue.pop_front();
      const Tri& tri = triangles_[t];
      for (int i = 0; i < 3; ++i) {
        const int n = tri.nb[i];
        if (n < 0) continue;
        const bool crosses = constrained_.count(edge_key(tri.v[(i + 1) % 3], tri.v[(i + 2) % 3]));
        const int d = depth[t] + (crosses ? 1 : 0);
        if (depth[n] != -1 && depth[n] <= d) continue;
        depth[n] = d;
        crosses ? queue.push_back(n) : queue.push_front(n);
      }
    }
    std::vector<std::array<std::uint32_t, 3>> inside;
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      const Tri& tri = triangles_[t];
      if (!tri.alive || touches_enclosing(tri) || depth[t] % 2 == 0) continue;
      inside.push_back({static_cast<std::uint32_t>(tri.v[0]), static_cast<std::uint32_t>(tri.v[1]),
                        static_cast<std::uint32_t>(tri.v[2])});
    }
    return inside;
  }

 private:
  struct Tri {
    std::array<int, 3> v;   // counter-clockwise
    std::array<int, 3> nb;  // nb[i]: triangle across the edge opposite v[i], -1 for none
    bool alive;
  };

  bool touches_enclosing(const Tri& t) const {
    return t.v[0] >= real_count_ || t.v[1] >= real_count_ || t.v[2] >= real_count_;
  }
  double orient_edge(const Tri& t, int i, const Point2& p) const {
    return orient(points_[t.v[(i + 1) % 3]], points_[t.v[(i + 2) % 3]], p);
  }

  int locate(const Point2& p) const {
    int t = last_;
    for (std::size_t steps = 0; steps < 4 * triangles_.size() + 16; ++steps) {
      const Tri& tri = triangles_[t];
      int next = -2;
      for (int k = 0; k < 3; ++k) {
        const int i = static_cast<int>((k + steps) % 3);  // rotating start avoids walk cycles
        if (orient_edge(tri, i, p) < -orient_eps_) {
          next = tri.nb[i];
          break;
        }
      }
      if (next == -2) return t;
      if (next < 0) break;
      t = next;
    }
    for (std::size_t s = 0; s < triangles_.size(); ++s) {  // fallback: exhaustive search
      const Tri& tri = triangles_[s];
      if (!tri.alive) continue;
      if (orient_edge(tri, 0, p) >= -orient_eps_ && orient_edge(tri, 1, p) >= -orient_eps_ &&
          orient_edge(tri, 2, p) >= -orient_eps_) {
        return static_cast<int>(s);
      }
    }
    throw std::logic_error("planar triangulation: point outside the enclosing triangle");
  }

  void insert(int pi) {
    const Point2& p = points_[pi];
    const int seed = locate(p);
    ++stamp_;
    if (mark_.size() < triangles_.size()) mark_.resize(triangles_.size(), 0);
    std::vector<int> cavity{seed};
    std::vector<int> protected_tris{seed};
    mark_[seed] = stamp_;
    // A point on an edge of the seed must take the triangle across too, or it would create a
    // triangle of zero area.
    for (int i = 0; i < 3; ++i) {
      const int n = triangles_[seed].nb[i];
      if (n >= 0 && std::abs(orient_edge(triangles_[seed], i, p)) <= orient_eps_ &&
          mark_[n] != stamp_) {
        mark_[n] = stamp_;
        cavity.push_back(n);
        protected_tris.push_back(n);
      }
    }
    for (std::size_t k = 0; k < cavity.size(); ++k) {
      const Tri& tri = triangles_[cavity[k]];
      for (int i = 0; i < 3; ++i) {
        const int n = tri.nb[i];
        if (n < 0 || mark_[n] == stamp_) continue;
        const Tri& other = triangles_[n];
        if (incircle(points_[other.v[0]], points_[other.v[1]], points_[other.v[2]], p) >
            incircle_eps_) {
          mark_[n] = stamp_;
          cavity.push_back(n);
        }
      }
    }
    trim_to_star_shape(cavity, protected_tris, p);

    struct BoundaryEdge {
      int a, b, outside;
    };
    std::vector<BoundaryEdge> boundary;
    for (int c : cavity) {
      const Tri& tri = triangles_[c];
      for (int i = 0; i < 3; ++i) {
        const int n = tri.nb[i];
        if (n >= 0 && mark_[n] == stamp_) continue;
        boundary.push_back({tri.v[(i + 1) % 3], tri.v[(i + 2) % 3], n});
      }
    }
    // New triangles take slots freed by earlier insertions only, so that no index below refers
    // to two triangles at once.
    std::vector<int> created;
    for (const BoundaryEdge& e : boundary) {
      int slot;
      if (!free_.empty()) {
        slot = free_.back();
        free_.pop_back();
      } else {
        slot = static_cast<int>(triangles_.size());
        triangles_.push_back({});
        mark_.push_back(0);
      }
      triangles_[slot] = {{e.a, e.b, pi}, {-1, -1, e.outside}, true};
      if (e.outside >= 0) relink(e.outside, e.a, e.b, slot);
      created.push_back(slot);
    }
    for (int s : created) {
      Tri& tri = triangles_[s];
      for (int o : created) {
        if (triangles_[o].v[0] == tri.v[1]) tri.nb[0] = o;  // shares edge b-p
        if (triangles_[o].v[1] == tri.v[0]) tri.nb[1] = o;  // shares edge p-a
      }
    }
    for (int c : cavity) {
      triangles_[c].alive = false;
      free_.push_back(c);
    }
    last_ = created.front();
  }

  /// Drops cavity triangles until every boundary edge of the cavity sees p on its inner side.
  void trim_to_star_shape(std::vector<int>& cavity, const std::vector<int>& protected_tris,
                          const Point2& p) {
    auto is_protected = [&](int t) {
      return std::find(protected_tris.begin(), protected_tris.end(), t) != protected_tris.end();
    };
    for (bool changed = true; changed;) {
      changed = false;
      for (int c : cavity) {
        if (is_protected(c) || mark_[c] != stamp_) continue;
        const Tri& tri = triangles_[c];
        for (int i = 0; i < 3; ++i) {
          const int n = tri.nb[i];
          if ((n < 0 || mark_[n] != stamp_) && orient_edge(tri, i, p) <= orient_eps_) {
            mark_[c] = 0;
            changed = true;
            break;
          }
        }
      }
      if (!changed) break;
      // Removing triangles may have cut some off from the seed: keep the connected part.
      std::vector<int> kept{cavity.front()};
      const std::uint32_t previous = stamp_;
      ++stamp_;
      mark_[cavity.front()] = stamp_;
      for (std::size_t k = 0; k < kept.size(); ++k) {
        for (int n : triangles_[kept[k]].nb) {
          if (n >= 0 && mark_[n] == previous) {
            mark_[n] = stamp_;
            kept.push_back(n);
          }
        }
      }
      cavity = std::move(kept);
    }
  }

  /// In triangle t, the neighbour across edge {a, b} becomes `replacement`.
  void relink(int t, int a, int b, int replacement) {
    Tri& tri = triangles_[t];
    for (int i = 0; i < 3; ++i) {
      const int u = tri.v[(i + 1) % 3], w = tri.v[(i + 2) % 3];
      if ((u == a && w == b) || (u == b && w == a)) {
        tri.nb[i] = replacement;
        return;
      }
    }
    throw std::logic_error("planar triangulation: broken adjacency");
  }

  bool has_edge(int a, int b) const {
    for (const Tri& tri : triangles_) {
      if (!tri.alive) continue;
      for (int i = 0; i < 3; ++i) {
        const int u = tri.v[i], w = tri.v[(i + 1) % 3];
        if ((u == a && w == b) || (u == b && w == a)) return true;
      }
    }
    return false;
  }

  bool flip_one_crossing_edge(int a, int b) {
    const Point2 &pa = points_[a], &pb = points_[b];
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
      const Tri& tri = triangles_[t];
      if (!tri.alive) continue;
      for (int i = 0; i < 3; ++i) {
        const int q = tri.v[(i + 1) % 3], r = tri.v[(i + 2) % 3], n = tri.nb[i];
        if (n < 0 || q == a || q == b || r == a || r == b) continue;
        if (constrained_.count(edge_key(q, r))) continue;
        const Point2 &pq = points_[q], &pr = points_[r];
        const bool crosses = orient(pa, pb, pq) * orient(pa, pb, pr) < 0 &&
                             orient(pq, pr, pa) * orient(pq, pr, pb) < 0;
        if (!crosses) continue;
        const int p = tri.v[i];
        const int w = opposite_vertex(n, q, r);
        // Only a strictly convex quadrilateral can be flipped.
        if (orient(points_[p], points_[w], pq) * orient(points_[p], points_[w], pr) >= 0) continue;
        if (orient(points_[p], pq, points_[w]) <= orient_eps_ ||
            orient(points_[p], points_[w], pr) <= orient_eps_) {
          continue;
        }
        flip(static_cast<int>(t), i);
        return true;
      }
    }
    return false;
  }

  int opposite_vertex(int t, int q, int r) const {
    for (int v : triangles_[t].v) {
      if (v != q && v != r) return v;
    }
    throw std::logic_error("planar triangulation: degenerate triangle");
  }

  /// Replaces triangles t = (p, q, r) and u = (w, r, q), sharing edge q-r opposite p = t.v[i],
  /// by (p, q, w) in slot t and (p, w, r) in slot u.
  void flip(int t, int i) {
    const Tri old_t = triangles_[t];
    const int u = old_t.nb[i];
    const Tri old_u = triangles_[u];
    const int p = old_t.v[i], q = old_t.v[(i + 1) % 3], r = old_t.v[(i + 2) % 3];
    int k = 0;
    while (old_u.v[k] == q || old_u.v[k] == r) ++k;
    const int w = old_u.v[k];
    const int across_rp = old_t.nb[(i + 1) % 3], across_pq = old_t.nb[(i + 2) % 3];
    const int across_qw = old_u.nb[(k + 1) % 3], across_wr = old_u.nb[(k + 2) % 3];
    triangles_[t] = {{p, q, w}, {across_qw, u, across_pq}, true};
    triangles_[u] = {{p, w, r}, {across_wr, across_rp, t}, true};
    if (across_qw >= 0) relink(across_qw, q, w, t);
    if (across_rp >= 0) relink(across_rp, r, p, u);
  }

  std::vector<Point2> points_;
  int real_count_;
  double orient_eps_ = 0, incircle_eps_ = 0;
  std::vector<Tri> triangles_;
  std::vector<int> free_;
  std::vector<std::uint32_t> mark_;
  std::uint32_t stamp_ = 0;
  int last_ = 0;
  std::unordered_set<std::uint64_t> constrained_;
};

struct Segment {
  Point2 a, b;
};

bool inside_even_odd(const Point2& p, const std::vector<Segment>& segments) {
  bool inside = false;
  for (const Segment& s : segments) {
    if ((s.a.y > p.y) != (s.b.y > p.y)) {
      const double x = s.a.x + (p.y - s.a.y) * (s.b.x - s.a.x) / (s.b.y - s.a.y);
      if (x > p.x) inside = !inside;
    }
  }
  return inside;
}

std::vector<Segment> loop_segments(const std::vector<Point2>& loop) {
  std::vector<Segment> segments;
  for (std::size_t k = 0; k < loop.size(); ++k)
    segments.push_back({loop[k], loop[(k + 1) % loop.size()]});
  return segments;
}

double distance_to_segments(const Point2& p, const std::vector<Segment>& segments) {
  double best = INFINITY;
  for (const Segment& s : segments) best = std::min(best, segment_distance(p, s.a, s.b));
  return best;
}

/// Answers "is p within `radius` of a segment?" by looking only at the segments of nearby cells.
class SegmentGrid {
 public:
  SegmentGrid(const std::vector<Segment>& segments, double radius)
      : segments_(segments), cell_(radius) {
    min_x_ = min_y_ = INFINITY;
    double max_x = -INFINITY, max_y = -INFINITY;
    for (const Segment& s : segments) {
      min_x_ = std::min({min_x_, s.a.x, s.b.x}), max_x = std::max({max_x, s.a.x, s.b.x});
      min_y_ = std::min({min_y_, s.a.y, s.b.y}), max_y = std::max({max_y, s.a.y, s.b.y});
    }
    columns_ = static_cast<long>((max_x - min_x_) / cell_) + 1;
    rows_ = static_cast<long>((max_y - min_y_) / cell_) + 1;
    cells_.resize(static_cast<std::size_t>(columns_ * rows_));
    for (std::size_t k = 0; k < segments.size(); ++k) {
      const Segment& s = segments[k];
      for (long r = row(std::min(s.a.y, s.b.y)); r <= row(std::max(s.a.y, s.b.y)); ++r) {
        for (long c = column(std::min(s.a.x, s.b.x)); c <= column(std::max(s.a.x, s.b.x)); ++c) {
          cells_[static_cast<std::size_t>(r * columns_ + c)].push_back(k);
        }
      }
    }
  }

  bool near(const Point2& p) const {
    // Segments within `radius` of p touch one of the 3 x 3 cells around p's cell.
    const long pr = row(p.y), pc = column(p.x);
    for (long r = std::max(0L, pr - 1); r <= std::min(rows_ - 1, pr + 1); ++r) {
      for (long c = std::max(0L, pc - 1); c <= std::min(columns_ - 1, pc + 1); ++c) {
        for (std::size_t k : cells_[static_cast<std::size_t>(r * columns_ + c)]) {
          if (segment_distance(p, segments_[k].a, segments_[k].b) < cell_) return true;
        }
      }
    }
    return false;
  }

 private:
  long row(double y) const {
    return std::clamp(static_cast<long>(std::floor((y - min_y_) / cell_)), -1L, rows_);
  }
  long column(double x) const {
    return std::clamp(static_cast<long>(std::floor((x - min_x_) / cell_)), -1L, columns_);
  }

  const std::vector<Segment>& segments_;
  double cell_;
  double min_x_, min_y_;
  long columns_ = 0, rows_ = 0;
  std::vector<std::vector<std::size_t>> cells_;
};

/// Vertices of a triangular lattice of spacing h inside the domain, kept clear of its
/// boundary so that no sliver forms against a boundary edge. Rows run along the first edge of
/// the outer loop, which lines the lattice up with straight outer boundaries.
std::vector<Point2> lattice_points(const std::vector<std::vector<Point2>>& loops,
                                   const std::vector<Segment>& segments, double h) {
  const Point2 origin = loops[0][0];
  const double ex = loops[0][1].x - origin.x, ey = loops[0][1].y - origin.y;
  const double len = std::hypot(ex, ey);
  const double ux = ex / len, uy = ey / len;  // lattice row direction; (-uy, ux) across rows
  // The domain in lattice coordinates (s along rows, t across).
  std::vector<Segment> rotated;
  for (const Segment& seg : segments) {
    auto to_lattice = [&](const Point2& p) {
      return Point2{(p.x - origin.x) * ux + (p.y - origin.y) * uy,
                    -(p.x - origin.x) * uy + (p.y - origin.y) * ux};
    };
    rotated.push_back({to_lattice(seg.a), to_lattice(seg.b)});
  }
  double min_s = INFINITY, max_s = -INFINITY, min_t = INFINITY, max_t = -INFINITY;
  for (const Segment& seg : rotated) {
    min_s = std::min({min_s, seg.a.x, seg.b.x}), max_s = std::max({max_s, seg.a.x, seg.b.x});
    min_t = std::min({min_t, seg.a.y, seg.b.y}), max_t = std::max({max_t, seg.a.y, seg.b.y});
  }
  const double row_step = h * std::sqrt(3.0) / 2;
  const SegmentGrid boundary(rotated, 0.5 * h);
  std::vector<Point2> points;
  const auto first_row = static_cast<long>(std::floor(min_t / row_step));
  const auto last_row = static_cast<long>(std::ceil(max_t / row_step));
  std::vector<double> crossings;
  for (long row = first_row; row <= last_row; ++row) {
    const double t = static_cast<double>(row) * row_step;
    // Even-odd rule along the row: a point is inside when an odd number of crossings lie
    // beyond it.
    crossings.clear();
    for (const Segment& seg : rotated) {
      if ((seg.a.y > t) != (seg.b.y > t)) {
        crossings.push_back(seg.a.x + (t - seg.a.y) * (seg.b.x - seg.a.x) / (seg.b.y - seg.a.y));
      }
    }
    std::sort(crossings.begin(), crossings.end());
    const double shift = (row % 2 == 0) ? 0.0 : 0.5 * h;
    const auto first_col = static_cast<long>(std::floor((min_s - shift) / h));
    const auto last_col = static_cast<long>(std::ceil((max_s - shift) / h));
    for (long col = first_col; col <= last_col; ++col) {
      const double s = static_cast<double>(col) * h + shift;
      const auto beyond = crossings.end() - std::upper_bound(crossings.begin(), crossings.end(), s);
      if (beyond % 2 == 0) continue;
      const Point2 lattice{s, t};
      if (boundary.near(lattice)) continue;
      points.push_back({origin.x + s * ux - t * uy, origin.y + s * uy + t * ux});
    }
  }
  return points;
}

/// Laplacian smoothing of the interior vertices (indices >= first_interior), moving a vertex
/// only when none of its triangles would fold over.
void smooth(std::vector<Point2>& points, std::size_t first_interior, std::size_t interior_end,
            const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  std::vector<std::vector<std::uint32_t>> neighbours(points.size()), incident(points.size());
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t v = triangles[t][i];
      incident[v].push_back(t);
      for (int j = 1; j < 3; ++j) {
        const std::uint32_t w = triangles[t][(i + j) % 3];
        if (std::find(neighbours[v].begin(), neighbours[v].end(), w) == neighbours[v].end()) {
          neighbours[v].push_back(w);
        }
      }
    }
  }
  for (int iteration = 0; iteration < 8; ++iteration) {
    for (std::size_t v = first_interior; v < interior_end; ++v) {
      if (neighbours[v].empty()) continue;
      Point2 average{0, 0};
      for (std::uint32_t w : neighbours[v]) average.x += points[w].x, average.y += points[w].y;
      average.x /= static_cast<double>(neighbours[v].size());
      average.y /= static_cast<double>(neighbours[v].size());
      const Point2 previous = points[v];
      points[v] = average;
      for (std::uint32_t t : incident[v]) {
        const auto& tri = triangles[t];
        const Point2 &a = points[tri[0]], &b = points[tri[1]], &c = points[tri[2]];
        const double area2 = orient(a, b, c);
        const double longest2 = std::max({(a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y),
                                          (b.x - c.x) * (b.x - c.x) + (b.y - c.y) * (b.y - c.y),
                                          (c.x - a.x) * (c.x - a.x) + (c.y - a.y) * (c.y - a.y)});
        if (area2 <= 0.05 * longest2) {  // folded or nearly flat: keep the old position
          points[v] = previous;
          break;
        }
      }
    }
  }
}

}  // namespace

PlanarTriangulation triangulate_planar_domain(const std::vector<std::vector<Point2>>& loops,
                                              double target_edge) {
  std::vector<Point2> points;
  std::vector<std::pair<int, int>> boundary_edges;
  std::vector<Segment> segments;
  for (const auto& loop : loops) {
    const int start = static_cast<int>(points.size());
    const int n = static_cast<int>(loop.size());
    for (int k = 0; k < n; ++k) boundary_edges.emplace_back(start + k, start + (k + 1) % n);
    points.insert(points.end(), loop.begin(), loop.end());
    const auto loop_segs = loop_segments(loop);
    segments.insert(segments.end(), loop_segs.begin(), loop_segs.end());
  }
  const std::size_t boundary_count = points.size();

  PlanarTriangulation result;
  if (target_edge > 0) result.interior_points = lattice_points(loops, segments, target_edge);
  points.insert(points.end(), result.interior_points.begin(), result.interior_points.end());
  const std::size_t interior_end = points.size();

  // A vertex in the middle of each hole (discarded with the hole's triangles) breaks the
  // co-circularity of sampled circular holes, which floating-point Delaunay handles poorly.
  for (std::size_t l = 1; l < loops.size(); ++l) {
    Point2 centre{0, 0};
    for (const Point2& p : loops[l]) centre.x += p.x, centre.y += p.y;
    centre.x /= static_cast<double>(loops[l].size());
    centre.y /= static_cast<double>(loops[l].size());
    const auto hole = loop_segments(loops[l]);
    double size = 0;
    for (const Segment& s : hole) size += std::hypot(s.b.x - s.a.x, s.b.y - s.a.y);
    if (inside_even_odd(centre, hole) && distance_to_segments(centre, hole) > 0.05 * size) {
      points.push_back(centre);
    }
  }

  auto triangulate = [&](const std::vector<Point2>& pts) {
    ConstrainedDelaunay cdt(pts);
    cdt.constrain(boundary_edges);
    return cdt.inside_triangles();
  };
  result.triangles = triangulate(points);
  if (interior_end > boundary_count) {
    smooth(points, boundary_count, interior_end, result.triangles);
    result.triangles = triangulate(points);
    std::copy(points.begin() + static_cast<std::ptrdiff_t>(boundary_count),
              points.begin() + static_cast<std::ptrdiff_t>(interior_end),
              result.interior_points.begin());
  }
  return result;
}

}  // namespace primseg::shape_detail
