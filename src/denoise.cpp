#include "primseg/denoise.hpp"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <string>

#include "cluster_numbering.hpp"
#include "eigen_conversions.hpp"
#include "no_index.hpp"
#include "ordered_pipeline.hpp"
#include "orientation_repair.hpp"
#include "parallel.hpp"
#include "primseg/error.hpp"
#include "primseg/geometric_fit.hpp"
#include "regularity.hpp"
#include "shape_generator/random.hpp"
#include "vertex_triangles.hpp"

namespace primseg {
namespace {

// Relabelling weighs, for each face, the clusters at its corners; a corner at more clusters than
// this offers none (DenoiseOptions::relabel_passes). Vertices of real meshes are at a handful.
constexpr std::size_t kMaxRelabelClustersAtVertex = 64;

// DenoiseOptions::ensemble_members at most: each member is a hierarchy and a snap.
constexpr int kMaxEnsembleMembers = 64;
// The stream of the ensemble's jitter: member m draws from kEnsembleSeed + m.
constexpr std::uint64_t kEnsembleSeed = 0x656e73656d626c65ull;
// Thrown into a member's build made ahead when the ensemble stops early (an error, Ctrl-C).
struct EnsembleStopped {};

using detail::to_eigen;
using detail::to_vec3;

Eigen::Vector3d triangle_normal(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                const Eigen::Vector3d& c) {
  return (b - a).cross(c - a);
}

// The report's moved vertices (those whose position changed) and their mean and largest move.
void measure_moves(std::span<const Vec3> start, std::span<const Vec3> end, SnapReport& report) {
  report.moved = 0;
  report.max_move = 0;
  double move_sum = 0;
  for (std::size_t v = 0; v < start.size(); ++v) {
    if (end[v] == start[v]) continue;
    const double move = (to_eigen(end[v]) - to_eigen(start[v])).norm();
    ++report.moved;
    move_sum += move;
    report.max_move = std::max(report.max_move, move);
  }
  report.mean_move = report.moved ? move_sum / report.moved : 0;
}

// Unit normal of the primitive's surface at `on_surface` (one of its closest points), or zero
// where the surface has none (a cone's apex, an axis point of a degenerate fit).
Eigen::Vector3d surface_normal(const Primitive& primitive, const Eigen::Vector3d& on_surface) {
  const Eigen::Vector3d origin = to_eigen(primitive.point);
  const Eigen::Vector3d axis = to_eigen(primitive.axis);
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  switch (primitive.type) {
    case PrimitiveType::Plane:
      normal = axis;
      break;
    case PrimitiveType::Sphere:
      normal = on_surface - origin;
      break;
    case PrimitiveType::Cylinder: {
      const Eigen::Vector3d d = on_surface - origin;
      normal = d - axis * axis.dot(d);
      break;
    }
    case PrimitiveType::Cone: {
      const Eigen::Vector3d d = on_surface - origin;
      const Eigen::Vector3d radial = d - axis * axis.dot(d);
      if (radial.squaredNorm() > 0)
        normal = radial.normalized() * std::cos(primitive.half_angle) -
                 axis * std::sin(primitive.half_angle);
      break;
    }
    case PrimitiveType::Torus: {
      const Eigen::Vector3d d = on_surface - origin;
      const Eigen::Vector3d radial = d - axis * axis.dot(d);
      if (radial.squaredNorm() > 0) normal = d - radial.normalized() * primitive.radius;
      break;
    }
  }
  const double length = normal.norm();
  return length > 0 && std::isfinite(length) ? Eigen::Vector3d(normal / length)
                                             : Eigen::Vector3d::Zero();
}

// The point nearest to x (approximately, for curved primitives) among the minimisers of the sum
// of squared distances to `primitives`: Gauss–Newton on the tangent planes at the closest points,
// each step the minimum-norm solution of the truncated normal equations. It stops when a step is
// at round-off against |y| + `length`, a length of the neighbourhood (so that the result does not
// depend on the units).
Eigen::Vector3d least_squares_point(const Eigen::Vector3d& x,
                                    const std::vector<const Primitive*>& primitives,
                                    double eigenvalue_ratio, int max_steps, double length) {
  if (primitives.size() == 1) return to_eigen(primitives[0]->closest_point(to_vec3(x)));
  Eigen::Vector3d y = x;
  for (int step = 0; step < max_steps; ++step) {
    Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Zero();
    Eigen::Vector3d right_side = Eigen::Vector3d::Zero();
    for (const Primitive* primitive : primitives) {
      const Eigen::Vector3d closest = to_eigen(primitive->closest_point(to_vec3(y)));
      const Eigen::Vector3d n = surface_normal(*primitive, closest);
      normal_matrix += n * n.transpose();
      right_side -= n * n.dot(y - closest);
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(normal_matrix);
    const Eigen::Vector3d& values = eigen.eigenvalues();  // increasing
    const double largest = values(2);
    if (!(largest > 0)) break;
    Eigen::Vector3d delta = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      if (values(k) > largest * eigenvalue_ratio) {
        const Eigen::Vector3d u = eigen.eigenvectors().col(k);
        delta += u * (u.dot(right_side) / values(k));
      }
    y += delta;
    if (!(delta.norm() > 1e-14 * (length + y.norm()))) break;
  }
  return y;
}

// Weighted least-squares plane through points (PCA), its normal on the side of `reference`;
// nullopt when the points do not span a plane.
std::optional<Primitive> fit_plane(std::span<const Vec3> points, std::span<const double> weights,
                                   const Eigen::Vector3d& reference) {
  double total = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    total += weights[i];
    centroid += weights[i] * to_eigen(points[i]);
  }
  if (points.size() < 3 || !(total > 0)) return std::nullopt;
  centroid /= total;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d d = to_eigen(points[i]) - centroid;
    scatter += weights[i] * d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  // The two in-plane spreads must be real, or the points are (nearly) on a line.
  if (!(eigen.eigenvalues()(1) > 1e-6 * eigen.eigenvalues()(2))) return std::nullopt;
  Eigen::Vector3d normal = eigen.eigenvectors().col(0);
  if (normal.dot(reference) < 0) normal = -normal;
  Primitive plane;
  plane.type = PrimitiveType::Plane;
  plane.point = to_vec3(centroid);
  plane.axis = to_vec3(normal);
  return plane;
}

// The largest RMS distance estimate of a segmentation's clusters (input units).
double worst_cluster_rms(const Hierarchy& hierarchy, const Segmentation& segmentation) {
  double worst = 0;
  for (const std::uint32_t node : segmentation.nodes)
    worst = std::max(worst, hierarchy.rms_estimate(node));
  return worst;
}

// The sizes that make a curved primitive a surface: finite and positive radii, a cone's half-angle
// strictly between 0 and 90 degrees.
bool has_valid_size(const Primitive& p) {
  switch (p.type) {
    case PrimitiveType::Plane:
      return true;
    case PrimitiveType::Sphere:
    case PrimitiveType::Cylinder:
      return p.radius > 0 && std::isfinite(p.radius);
    case PrimitiveType::Cone:
      return p.half_angle > 0 && p.half_angle < std::numbers::pi / 2;
    case PrimitiveType::Torus:
      return p.radius > 0 && std::isfinite(p.radius) && p.minor_radius > 0 &&
             std::isfinite(p.minor_radius);
  }
  return false;
}

// Parameters of a curved type as Primitive stores them (a cylinder's point and axis 3 each).
std::size_t parameter_count(PrimitiveType type) {
  switch (type) {
    case PrimitiveType::Plane:
      return 6;
    case PrimitiveType::Sphere:
      return 4;
    case PrimitiveType::Cylinder:
    case PrimitiveType::Cone:
      return 7;
    case PrimitiveType::Torus:
      return 8;
  }
  return 8;
}

// Geometric least-squares refinement of a curved primitive (fit_geometric_or_sphere: a torus
// whose ring vanishes comes back as the sphere of its tube, which is what the snap moves vertices
// onto and what snapped_level() reports); nullopt when it does not lower the error, or for fewer
// than two points per stored parameter, where a curved fit follows the noise.
std::optional<Primitive> fit_curved(const Primitive& start, std::span<const Vec3> points,
                                    std::span<const double> weights) {
  if (points.size() < 2 * parameter_count(start.type) || !has_valid_size(start))
    return std::nullopt;
  const GeometricFit fit = fit_geometric_or_sphere(start, points, weights);
  if (fit.iterations == 0 || !has_valid_size(fit.primitive)) return std::nullopt;
  return fit.primitive;
}

}  // namespace

void validate(const DenoiseOptions& options) {
  if (!(options.max_move_edge_lengths > 0))
    throw InvalidInputError("denoise: the largest move must be a positive number of edge lengths");
  if (!(options.min_crease_angle_degrees >= 0 && options.min_crease_angle_degrees < 90))
    throw InvalidInputError("denoise: the smallest crease angle must be in [0, 90) degrees");
  if (!(options.refit_outlier_threshold >= 0) || !std::isfinite(options.refit_outlier_threshold))
    throw InvalidInputError("denoise: the refit outlier threshold must be a non-negative number");
  if (options.smoothing_steps < 0)
    throw InvalidInputError("denoise: the smoothing steps must be a non-negative count");
  if (options.bilateral_smoothing) {
    validate(*options.bilateral_smoothing);
    if (options.smoothing_steps > 0)
      throw InvalidInputError("denoise: choose Taubin or bilateral smoothing, not both");
  }
  if (options.noise_tolerance_factor &&
      !(*options.noise_tolerance_factor > 0 && std::isfinite(*options.noise_tolerance_factor)))
    throw InvalidInputError("denoise: the noise tolerance factor must be a positive number");
  if (!(options.relation_significance >= 0) || !std::isfinite(options.relation_significance))
    throw InvalidInputError("denoise: the relation significance must be a non-negative number");
  if (options.relabel_passes < 0)
    throw InvalidInputError("denoise: the relabelling passes must be a non-negative count");
  if (options.max_solver_steps < 1)
    throw InvalidInputError("denoise: the solver needs at least one step");
  if (options.ensemble_members < 1 || options.ensemble_members > kMaxEnsembleMembers)
    throw InvalidInputError("denoise: the ensemble must have 1 to " +
                            std::to_string(kMaxEnsembleMembers) + " members, not " +
                            std::to_string(options.ensemble_members));
  if (!(options.ensemble_jitter > 0 && options.ensemble_jitter <= 1))
    throw InvalidInputError(
        "denoise: the ensemble's jitter must be in (0, 1] estimated noise deviations");
  if (options.ensemble_members > 1 && options.mode == SnapMode::NearestIncident)
    throw InvalidInputError(
        "denoise: an ensemble averages snaps, which would take stylized vertices off their "
        "primitives; stylize with one member");
  validate(options.hierarchy);
}

LevelSelector level_by_count(std::uint32_t clusters) {
  return [clusters](const Hierarchy& hierarchy) { return cut_by_count(hierarchy, clusters); };
}

LevelSelector level_by_tolerance(double tolerance) {
  return [tolerance](const Hierarchy& hierarchy) { return cut_by_tolerance(hierarchy, tolerance); };
}

Denoiser::Denoiser(Mesh mesh, DenoiseOptions options)
    : mesh_(std::move(mesh)), options_(std::move(options)) {
  validate(options_);
  mesh_.validate();
  check_geometric_range(mesh_);
  const std::uint32_t n = mesh_.vertex_count();
  input_normals_.reserve(mesh_.triangles.size());
  std::vector<double> edge_sum(n, 0);
  std::vector<std::uint32_t> edge_count(n, 0);
  for (const Triangle& t : mesh_.triangles) {
    const Eigen::Vector3d a = to_eigen(mesh_.positions[t[0]]), b = to_eigen(mesh_.positions[t[1]]),
                          c = to_eigen(mesh_.positions[t[2]]);
    const Vec3 normal = to_vec3(triangle_normal(a, b, c));
    input_normals_.push_back(normal);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = t[k], v = t[(k + 1) % 3];
      const double length = (to_eigen(mesh_.positions[u]) - to_eigen(mesh_.positions[v])).norm();
      edge_sum[u] += length;
      edge_sum[v] += length;
      ++edge_count[u];
      ++edge_count[v];
    }
  }
  VertexTriangles rows = vertex_triangles(mesh_);
  vertex_triangle_offsets_ = std::move(rows.offsets);
  vertex_triangles_ = std::move(rows.triangles);
  local_edge_length_.resize(n);
  for (std::uint32_t v = 0; v < n; ++v)
    local_edge_length_[v] = edge_count[v] ? edge_sum[v] / edge_count[v] : 0;
}

namespace {

// The options estimate_noise() smooths with, and whether `options` smooth the same (threads
// aside: the result does not depend on them).
const BilateralSmoothingOptions kEstimateSmoothing{};

bool smooths_as_the_estimate(BilateralSmoothingOptions options) {
  options.threads = kEstimateSmoothing.threads;
  return options == kEstimateSmoothing;
}

// RMS distance between the used vertices of `mesh` and their smoothed positions.
double noise_from(const Mesh& mesh, const Mesh& smoothed) {
  // Over the vertices of triangles only: an unused vertex does not move and is no sample.
  std::vector<char> used(mesh.vertex_count(), 0);
  for (const Triangle& t : mesh.triangles)
    for (const std::uint32_t v : t) used[v] = 1;
  double sum = 0;
  std::uint32_t count = 0;
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    if (!used[v]) continue;
    sum += (to_eigen(mesh.positions[v]) - to_eigen(smoothed.positions[v])).squaredNorm();
    ++count;
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

}  // namespace

std::shared_ptr<const Mesh> Denoiser::estimate_copy() const {
  const std::lock_guard lock(estimate_copy_.mutex);
  if (!estimate_copy_.copy) {
    BilateralSmoothingOptions options = kEstimateSmoothing;
    if (options_.bilateral_smoothing) options.threads = options_.bilateral_smoothing->threads;
    estimate_copy_.copy = std::make_shared<const Mesh>(bilateral_smooth(mesh_, options));
  }
  return estimate_copy_.copy;
}

std::shared_ptr<const Mesh> Denoiser::segmented_mesh() const {
  if (options_.bilateral_smoothing && smooths_as_the_estimate(*options_.bilateral_smoothing))
    return estimate_copy();
  return segmented_copy(mesh_);
}

std::shared_ptr<const Mesh> Denoiser::segmented_copy(const Mesh& mesh, unsigned threads) const {
  // Taubin's λ|μ smoothing with uniform weights over the edge neighbours: shrinks noise, not the
  // shape. Neighbours come from the triangles around each vertex (each edge seen twice: same
  // weights for all, so the average is unchanged).
  if (options_.bilateral_smoothing) {
    BilateralSmoothingOptions smoothing = *options_.bilateral_smoothing;
    if (threads > 0) smoothing.threads = threads;
    return std::make_shared<Mesh>(bilateral_smooth(mesh, smoothing));
  }
  constexpr double kLambda = 0.5, kMu = -0.53;
  auto segmented = std::make_shared<Mesh>(mesh);
  std::vector<Vec3>& positions = segmented->positions;
  std::vector<Vec3> next(positions.size());
  for (int step = 0; step < 2 * options_.smoothing_steps; ++step) {
    const double factor = step % 2 == 0 ? kLambda : kMu;
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int count = 0;
      for (std::uint32_t i = vertex_triangle_offsets_[v]; i < vertex_triangle_offsets_[v + 1]; ++i)
        for (const std::uint32_t u : mesh.triangles[vertex_triangles_[i]])
          if (u != v) {
            sum += to_eigen(positions[u]);
            ++count;
          }
      const Eigen::Vector3d x = to_eigen(positions[v]);
      next[v] = count ? to_vec3(x + factor * (sum / count - x)) : positions[v];
    }
    positions.swap(next);
  }
  return segmented;
}

double estimate_noise(const Mesh& mesh, const BilateralSmoothingOptions& options) {
  return noise_from(mesh, bilateral_smooth(mesh, options));
}

double Denoiser::noise_tolerance_factor() const {
  if (options_.noise_tolerance_factor) return *options_.noise_tolerance_factor;
  if (options_.bilateral_smoothing) return 0.4;
  return options_.smoothing_steps > 0 ? 0.8 : 1.2;
}

DenoiseLevel Denoiser::automatic_level(const Hierarchy& hierarchy) const {
  DenoiseLevel level;
  level.automatic = choose_level(hierarchy);
  const bool jump = level.automatic.rule == AutoLevelRule::Jump;
  // Stylization wants few clusters: the segmentation's own level.
  const bool stylize = options_.mode == SnapMode::NearestIncident;
  if (jump || stylize) level.segmentation = cut_by_count(hierarchy, level.automatic.clusters);
  if (stylize) return level;
  // Only here: the estimate smooths the whole mesh, once more unless the segmented copy is its.
  level.noise = noise_from(mesh_, *estimate_copy());
  level.tolerance = noise_tolerance_factor() * level.noise;
  // A cluster that fits several times worse than the noise allows straddles two surfaces, and
  // snapping onto its primitive moves vertices off both. Measured on the 13 generated shapes with
  // 0.2% and 0.4% noise, 2 seeds, as they are and with a bilateral copy (96 jump levels): the worst
  // cluster of a jump at the true number of surfaces is within 3.8 tolerances but once (5.6, where
  // the jump and the noise level denoise alike); the 6 jumps with a cluster beyond 4.5 tolerances
  // had left a region out and took the RMS distance to the clean shape above the noisy input's
  // (0.14x to 0.46x; 1.4x to 4.0x at the noise level). A chamfer that resampling left on a
  // noise-free part is systematic, not noise, and stays below it: the marching-tetrahedra box's
  // worst plane is at 4.0 tolerances on its bilateral copy, 2.1 as it is.
  if (jump) level.jump_worst_rms = worst_cluster_rms(hierarchy, level.segmentation);
  level.by_noise = !jump || level.jump_worst_rms > kMaxJumpClusterRmsInTolerances * level.tolerance;
  if (level.by_noise) level.segmentation = cut_by_tolerance(hierarchy, level.tolerance);
  return level;
}

SnapReport Denoiser::iterate(const LevelSelector& level) {
  const Hierarchy hierarchy = build_hierarchy(segmented_mesh(), options_.hierarchy);
  return snap(hierarchy, level(hierarchy), level);
}

SnapReport Denoiser::snap(const Hierarchy& hierarchy, const Segmentation& segmentation,
                          const LevelSelector& level) {
  const int members = options_.ensemble_members;
  if (members <= 1) return snap(hierarchy, segmentation);
  // The mesh before the snaps, which the members' builds read while this thread snaps.
  const Mesh unjittered = mesh_;
  const std::vector<Vec3>& start = unjittered.positions;
  // A snap resets the estimate's copy, which stays valid once the positions are put back: the
  // members' automatic levels need it, and smoothing it again each time would cost a member.
  const std::shared_ptr<const Mesh> estimate = estimate_copy();
  const double jitter = options_.ensemble_jitter * noise_from(mesh_, *estimate);
  // The members' hierarchies are built on a helper thread and on this one while this one snaps
  // (which calls `level`, perhaps into Python) member by member; each build then runs on one
  // thread, as two builds side by side keep both cores busier than one build on two. A member's
  // tree is a function of its number alone, so the mean does not depend on the threads.
  const bool on_two_threads = detail::thread_count(options_.hierarchy.threads) > 1;
  HierarchyOptions member_options = hierarchy.options();
  const unsigned member_threads = on_two_threads ? 1 : 0;
  if (on_two_threads) member_options.threads = 1;
  const auto build_member = [&](std::size_t index, const std::atomic<bool>& stop) {
    Mesh jittered = unjittered;
    shape_detail::SplitMix64 random(kEnsembleSeed + index + 1);
    for (std::size_t v = 0; v < start.size(); ++v)
      for (int d = 0; d < 3; ++d) jittered.positions[v][d] = start[v][d] + jitter * random.normal();
    return HierarchyBuilder(segmented_copy(jittered, member_threads), member_options)
        .finish([&stop](double) {
          if (stop) throw EnsembleStopped{};
        });
  };
  // The helper starts on the first members while this thread makes the first snap. At most three
  // hierarchies are made ahead of the one being snapped (two left the helper idle during snaps:
  // fandisk with 16 members 1.45 s against 1.31 s).
  detail::OrderedPipeline<Hierarchy> members_ahead(static_cast<std::size_t>(members - 1), 3,
                                                   on_two_threads, build_member);
  SnapReport report = snap(hierarchy, segmentation);
  const std::vector<Vec3> first = mesh_.positions;
  SnappedLevel first_level = std::move(snapped_level_);
  // The members' offsets from the first snap, summed in member order (the mean does not depend
  // on the threads): where every member agrees, as on a vertex no snap moves, the mean is the
  // first snap bit for bit.
  std::vector<Eigen::Vector3d> offset_sum(start.size(), Eigen::Vector3d::Zero());
  try {
    for (int member = 1; member < members; ++member) {
      const Hierarchy jittered = members_ahead.take();
      mesh_.positions = start;
      estimate_copy_.set(estimate);
      snap(jittered, level(jittered));
      for (std::size_t v = 0; v < start.size(); ++v)
        offset_sum[v] += to_eigen(mesh_.positions[v]) - to_eigen(first[v]);
    }
  } catch (...) {
    // The positions as before the call (`level` may throw: Python's Ctrl-C).
    mesh_.positions = start;
    estimate_copy_.set(estimate);
    snapped_level_ = {};
    throw;
  }
  for (std::size_t v = 0; v < start.size(); ++v)
    mesh_.positions[v] = to_vec3(to_eigen(first[v]) + offset_sum[v] / members);
  snapped_level_ = std::move(first_level);
  report.ensemble_members = static_cast<std::uint32_t>(members);
  report.reverted =
      revert_inverted_triangles(mesh_.positions, first, mesh_.triangles, input_normals_);
  measure_moves(start, mesh_.positions, report);
  return report;
}

void Denoiser::cluster_vertices(const Segmentation& segmentation, std::size_t cluster_count,
                                std::vector<std::vector<Vec3>>& points,
                                std::vector<std::vector<double>>& weights) const {
  // Every vertex of a cluster's faces, weighted by the area of its triangles in the cluster.
  points.assign(cluster_count, {});
  weights.assign(cluster_count, {});
  std::vector<std::pair<std::uint32_t, double>> area_by_cluster;
  const auto by_cluster = [](const auto& a, const auto& b) { return a.first < b.first; };
  for (std::uint32_t v = 0; v < mesh_.vertex_count(); ++v) {
    area_by_cluster.clear();
    for (std::uint32_t i = vertex_triangle_offsets_[v]; i < vertex_triangle_offsets_[v + 1]; ++i) {
      const std::uint32_t t = vertex_triangles_[i];
      const Triangle& corners = mesh_.triangles[t];
      area_by_cluster.emplace_back(segmentation.labels[mesh_.face_of_triangle[t]],
                                   triangle_normal(to_eigen(mesh_.positions[corners[0]]),
                                                   to_eigen(mesh_.positions[corners[1]]),
                                                   to_eigen(mesh_.positions[corners[2]]))
                                       .norm());
    }
    // Sorted, not searched: a vertex on d triangles of m clusters (a book's spine) costs
    // O(d log d), not O(d m). Stable, so each cluster's areas add up in triangle order.
    std::stable_sort(area_by_cluster.begin(), area_by_cluster.end(), by_cluster);
    for (std::size_t begin = 0; begin < area_by_cluster.size();) {
      const std::uint32_t c = area_by_cluster[begin].first;
      double area = area_by_cluster[begin].second;
      std::size_t end = begin + 1;
      for (; end < area_by_cluster.size() && area_by_cluster[end].first == c; ++end)
        area += area_by_cluster[end].second;
      points[c].push_back(mesh_.positions[v]);
      weights[c].push_back(area);
      begin = end;
    }
  }
}

void Denoiser::refit(const Segmentation& segmentation, std::vector<Primitive>& primitives) const {
  std::vector<std::vector<Vec3>> points;
  std::vector<std::vector<double>> weights;
  cluster_vertices(segmentation, primitives.size(), points, weights);
  const double floor = 1e-12 * bounding_box_diagonal(mesh_);
  // Each cluster on its own: the same result for any thread count.
  const unsigned threads = detail::thread_count(options_.hierarchy.threads);
  detail::parallel_for_threads(primitives.size(), threads, [&](std::size_t c, unsigned) {
    const PrimitiveType type = primitives[c].type;
    if (points[c].empty()) return;  // a cluster that relabelling emptied
    Primitive current = primitives[c];
    std::vector<Vec3> kept_points;
    std::vector<double> kept_weights;
    constexpr int kRounds = 3;
    for (int round = 0; round < kRounds; ++round) {
      detail::keep_inliers(current, points[c], weights[c], options_.refit_outlier_threshold, floor,
                           kept_points, kept_weights);
      const std::optional<Primitive> refit =
          type == PrimitiveType::Plane
              ? fit_plane(kept_points, kept_weights, to_eigen(current.axis))
              : fit_curved(current, kept_points, kept_weights);
      if (!refit) break;
      current = *refit;
    }
    primitives[c] = current;
  });
}

std::vector<ClusterRelation> Denoiser::regularize(const std::vector<std::vector<Vec3>>& points,
                                                  const std::vector<std::vector<double>>& weights,
                                                  std::vector<Primitive>& primitives) const {
  detail::RegularityOptions regularity;
  regularity.significance = options_.relation_significance;
  // Equal radii do not lower the error of a snap: fandisk (four noise draws), anchor_dense,
  // couplingdown and mech-holes-shark at the automatic level moved by -0.9% to +0.9% in RMS
  // (docs/method.md), so the denoiser keeps each cylinder's own radius. Nor do coplanar
  // fragments: the automatic levels of NumPy draws of fandisk and couplingdown moved by -0.4% to
  // 0%, but the C++ fandisk table's plain K = 40 by +1.6% and its Taubin K = 60 by +2.2%, so each
  // plane keeps its own offset. Spheres centred on axes do lower it (-0.1% to -1.2% on the same
  // runs where one was found, none worse), and stay; so do concentric spheres (couplingdown's
  // automatic level 1.6104e-3 → 1.6099e-3), each with its own radius.
  // Nor do tangent fillets (docs/method.md): -0.6% to +1.6% on the same automatic levels, and
  // the C++ fandisk table's K = 40 from 3.61x to 3.45x.
  regularity.equal_radii = false;
  regularity.coplanar = false;
  regularity.tangency = false;
  return detail::regularize_inliers(primitives, points, weights, options_.refit_outlier_threshold,
                                    1e-12 * bounding_box_diagonal(mesh_), regularity);
}

void Denoiser::relabel(const Mesh& judged, std::vector<Primitive>& primitives,
                       Segmentation& segmentation) const {
  if (options_.relabel_passes == 0) return;
  std::vector<std::uint32_t>& labels = segmentation.labels;
  // Face f's triangles are [face_offsets[f], face_offsets[f + 1]): a valid mesh's
  // face_of_triangle is non-decreasing.
  std::vector<std::uint32_t> face_offsets(mesh_.face_count() + 1, 0);
  for (const std::uint32_t f : mesh_.face_of_triangle) ++face_offsets[f + 1];
  for (std::uint32_t f = 0; f < mesh_.face_count(); ++f) face_offsets[f + 1] += face_offsets[f];
  const std::vector<Primitive> refit_starts = primitives;  // each pass refits from these
  std::vector<std::uint32_t> near, next;
  // The clusters at each vertex, each once: vertex v's are [cluster_offsets[v],
  // cluster_offsets[v + 1]) of clusters_at.
  std::vector<std::uint32_t> cluster_offsets(mesh_.vertex_count() + 1, 0), clusters_at;
  for (int pass = 0; pass < options_.relabel_passes; ++pass) {
    clusters_at.clear();
    for (std::uint32_t v = 0; v < mesh_.vertex_count(); ++v) {
      const auto begin = static_cast<std::ptrdiff_t>(clusters_at.size());
      for (std::uint32_t j = vertex_triangle_offsets_[v]; j < vertex_triangle_offsets_[v + 1]; ++j)
        clusters_at.push_back(labels[mesh_.face_of_triangle[vertex_triangles_[j]]]);
      std::sort(clusters_at.begin() + begin, clusters_at.end());
      clusters_at.erase(std::unique(clusters_at.begin() + begin, clusters_at.end()),
                        clusters_at.end());
      // A vertex at too many clusters (a book's spine, the hub of a finely cut fan) offers none:
      // its faces choose among the clusters at their other corners. Otherwise every face on it
      // would weigh them all, O(d²) on d triangles.
      if (clusters_at.size() - static_cast<std::size_t>(begin) > kMaxRelabelClustersAtVertex)
        clusters_at.resize(static_cast<std::size_t>(begin));
      cluster_offsets[v + 1] = static_cast<std::uint32_t>(clusters_at.size());
    }
    next = labels;
    bool changed = false;
    for (std::uint32_t f = 0; f < mesh_.face_count(); ++f) {
      near.assign(1, labels[f]);  // its own, even when every corner is at too many clusters
      for (std::uint32_t i = face_offsets[f]; i < face_offsets[f + 1]; ++i)
        for (const std::uint32_t v : mesh_.triangles[i])
          near.insert(near.end(), clusters_at.begin() + cluster_offsets[v],
                      clusters_at.begin() + cluster_offsets[v + 1]);
      std::sort(near.begin(), near.end());
      near.erase(std::unique(near.begin(), near.end()), near.end());
      if (near.size() < 2) continue;
      // The cluster whose primitive the face's corners are nearest to (sum of squared
      // distances); ties keep the lower label, the face's own first.
      double best_cost = std::numeric_limits<double>::infinity();
      std::uint32_t best = labels[f];
      for (const std::uint32_t c : near) {
        double cost = 0;
        for (std::uint32_t i = face_offsets[f]; i < face_offsets[f + 1]; ++i)
          for (const std::uint32_t v : mesh_.triangles[i]) {
            const double d = primitives[c].distance(judged.positions[v]);
            cost += d * d;
          }
        if (cost < best_cost || (cost == best_cost && c == labels[f])) {
          best_cost = cost;
          best = c;
        }
      }
      changed |= best != labels[f];
      next[f] = best;
    }
    labels.swap(next);
    if (!changed) break;
    primitives = refit_starts;
    if (options_.refit_outlier_threshold > 0) refit(segmentation, primitives);
  }
}

SnappedLevel Denoiser::describe_snap(const Segmentation& hierarchy_level,
                                     const Segmentation& relabelled,
                                     const std::vector<std::vector<Vec3>>& points,
                                     const std::vector<std::vector<double>>& weights,
                                     const std::vector<Primitive>& hierarchy_fits,
                                     const std::vector<Primitive>& primitives,
                                     std::vector<ClusterRelation> relations) const {
  const std::size_t k = primitives.size();
  std::vector<ClusterReport> reports(k);
  std::vector<std::uint32_t> lowest_face(k, detail::kNone);
  for (std::uint32_t f = 0; f < mesh_.face_count(); ++f) {
    const std::uint32_t c = relabelled.labels[f];
    ++reports[c].face_count;
    lowest_face[c] = std::min(lowest_face[c], f);
  }
  for (std::uint32_t t = 0; t < mesh_.triangle_count(); ++t) {
    const Triangle& corners = mesh_.triangles[t];
    reports[relabelled.labels[mesh_.face_of_triangle[t]]].area +=
        triangle_normal(to_eigen(mesh_.positions[corners[0]]),
                        to_eigen(mesh_.positions[corners[1]]),
                        to_eigen(mesh_.positions[corners[2]]))
            .norm() /
        2;
  }
  for (std::size_t c = 0; c < k; ++c) {
    ClusterReport& r = reports[c];
    r.node = hierarchy_level.nodes[c];
    r.primitive = primitives[c];
    r.algebraic = hierarchy_fits[c];
    double weighted_squares = 0, weight_sum = 0;
    for (std::size_t i = 0; i < points[c].size(); ++i) {
      const double d = primitives[c].distance(points[c][i]);
      weighted_squares += weights[c][i] * d * d;
      weight_sum += weights[c][i];
      if (weights[c][i] > 0) r.max = std::max(r.max, d);
    }
    r.rms = weight_sum > 0 ? std::sqrt(weighted_squares / weight_sum) : 0;
  }
  // Numbered as a Segmentation is, without the clusters relabelling emptied.
  std::vector<std::uint32_t> order;
  for (std::uint32_t c = 0; c < k; ++c)
    if (reports[c].face_count > 0) order.push_back(c);
  detail::sort_into_label_order(
      order, [&](std::uint32_t c) { return reports[c].area; },
      [&](std::uint32_t c) { return lowest_face[c]; });
  SnappedLevel level;
  std::vector<std::uint32_t> rank(k, detail::kNone);
  for (std::uint32_t r = 0; r < order.size(); ++r) {
    rank[order[r]] = r;
    level.clusters.push_back(reports[order[r]]);
    level.clusters.back().id = r;
  }
  level.labels.reserve(relabelled.labels.size());
  for (const std::uint32_t c : relabelled.labels) level.labels.push_back(rank[c]);
  // Related clusters have vertices, so none was emptied.
  for (ClusterRelation& relation : relations) {
    for (std::uint32_t& c : relation.clusters) c = rank[c];
    for (std::uint32_t& c : relation.orthogonal_to) c = rank[c];
    std::sort(relation.clusters.begin(), relation.clusters.end());
    std::sort(relation.orthogonal_to.begin(), relation.orthogonal_to.end());
    if (!relation.orthogonal_to.empty() && relation.orthogonal_to[0] < relation.clusters[0])
      std::swap(relation.clusters, relation.orthogonal_to);
  }
  detail::sort_relations(relations);
  level.relations = std::move(relations);
  return level;
}

SnapReport Denoiser::snap(const Hierarchy& hierarchy, const Segmentation& segmentation) {
  const Mesh& segmented = hierarchy.mesh();
  if (segmented.vertex_count() != mesh_.vertex_count() || segmented.triangles != mesh_.triangles ||
      segmented.face_of_triangle != mesh_.face_of_triangle)
    throw InvalidInputError("denoise: the hierarchy was not built on the mesh being denoised");
  if (segmentation.labels.size() != mesh_.face_count())
    throw InvalidInputError("denoise: the segmentation has " +
                            std::to_string(segmentation.labels.size()) + " labels for " +
                            std::to_string(mesh_.face_count()) + " faces");
  Segmentation labelled;
  const std::vector<Primitive> primitives = snap_primitives(hierarchy, segmentation, labelled);
  SnapReport report = move_vertices(labelled, primitives);
  report.clusters = static_cast<std::uint32_t>(snapped_level_.clusters.size());
  return report;
}

std::vector<Primitive> Denoiser::snap_primitives(const Hierarchy& hierarchy,
                                                 const Segmentation& level,
                                                 Segmentation& labelled) {
  const std::vector<Primitive> hierarchy_fits =
      cluster_primitives(describe_clusters(hierarchy, level));
  std::vector<Primitive> primitives = hierarchy_fits;
  if (options_.refit_outlier_threshold > 0) refit(level, primitives);
  labelled = level;
  relabel(hierarchy.mesh(), primitives, labelled);
  // The vertices of each final cluster, for the relations and the snapped level's reports.
  std::vector<std::vector<Vec3>> points;
  std::vector<std::vector<double>> weights;
  cluster_vertices(labelled, primitives.size(), points, weights);
  std::vector<ClusterRelation> relations;
  if (options_.relation_significance > 0 && options_.refit_outlier_threshold > 0)
    relations = regularize(points, weights, primitives);
  snapped_level_ = describe_snap(level, labelled, points, weights, hierarchy_fits, primitives,
                                 std::move(relations));
  return primitives;
}

void Denoiser::incident_clusters(std::uint32_t v, const Segmentation& labelled,
                                 const std::vector<Primitive>& primitives, const Vec3& position,
                                 std::vector<std::uint32_t>& clusters) const {
  clusters.clear();
  for (std::uint32_t i = vertex_triangle_offsets_[v]; i < vertex_triangle_offsets_[v + 1]; ++i)
    clusters.push_back(labelled.labels[mesh_.face_of_triangle[vertex_triangles_[i]]]);
  std::sort(clusters.begin(), clusters.end());
  clusters.erase(std::unique(clusters.begin(), clusters.end()), clusters.end());
  std::vector<std::pair<double, std::uint32_t>> by_distance;
  by_distance.reserve(clusters.size());
  for (const std::uint32_t c : clusters)
    by_distance.emplace_back(primitives[c].distance(position), c);
  std::sort(by_distance.begin(), by_distance.end());
  for (std::size_t i = 0; i < by_distance.size(); ++i) clusters[i] = by_distance[i].second;
}

bool Denoiser::keeps_orientation(std::uint32_t v, const Vec3& target) const {
  for (std::uint32_t i = vertex_triangle_offsets_[v]; i < vertex_triangle_offsets_[v + 1]; ++i) {
    const std::uint32_t t = vertex_triangles_[i];
    std::array<Eigen::Vector3d, 3> corner;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t u = mesh_.triangles[t][k];
      corner[k] = to_eigen(u == v ? target : mesh_.positions[u]);
    }
    if (turned_over(corner[0], corner[1], corner[2], input_normals_[t])) return false;
  }
  return true;
}

SnapReport Denoiser::move_vertices(const Segmentation& labelled,
                                   const std::vector<Primitive>& primitives) {
  SnapReport report;
  const double eigenvalue_ratio =
      std::pow(std::tan(options_.min_crease_angle_degrees * std::numbers::pi / 360), 2);
  const bool bounded =
      options_.mode == SnapMode::AllIncident && std::isfinite(options_.max_move_edge_lengths);
  const std::vector<Vec3> start = mesh_.positions;
  estimate_copy_.set(nullptr);  // of positions about to move

  constexpr double kRoundOffMove = 1e-12;
  const std::uint32_t n = mesh_.vertex_count();
  // 0: not yet settled, 1: snapped, 2: has no triangle.
  std::vector<char> settled(n, 0);
  std::vector<std::uint32_t> used_primitive_count(n, 0), incident_count(n, 0);
  std::vector<std::uint32_t> clusters;
  std::vector<const Primitive*> chosen;
  for (std::uint32_t v = 0; v < n; ++v) {
    if (vertex_triangle_offsets_[v] == vertex_triangle_offsets_[v + 1]) {
      settled[v] = 2;
      continue;
    }
    incident_clusters(v, labelled, primitives, start[v], clusters);
    incident_count[v] = static_cast<std::uint32_t>(clusters.size());
    (clusters.size() == 1 ? report.interior_vertices : report.boundary_vertices)++;
  }
  // A move blocked by a neighbour may pass once that neighbour has moved: the first sweeps try
  // only the full snap, the last one falls back to fewer primitives. Vertex order throughout.
  constexpr int kSweeps = 4;
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    const bool last_sweep = sweep == kSweeps - 1;
    bool changed = false;
    for (std::uint32_t v = 0; v < n; ++v) {
      if (settled[v]) continue;
      incident_clusters(v, labelled, primitives, start[v], clusters);
      const std::size_t most = options_.mode == SnapMode::AllIncident ? clusters.size() : 1;
      const Eigen::Vector3d x = to_eigen(start[v]);
      const double bound = options_.max_move_edge_lengths * local_edge_length_[v];
      const std::size_t fewest = last_sweep ? 1 : most;
      for (std::size_t count = most; count >= fewest; --count) {
        chosen.clear();
        for (std::size_t i = 0; i < count; ++i) chosen.push_back(&primitives[clusters[i]]);
        Eigen::Vector3d target = least_squares_point(
            x, chosen, eigenvalue_ratio, options_.max_solver_steps, local_edge_length_[v]);
        // A move at the round-off level of the fits and the solve is no move: a vertex already
        // on its primitives keeps its position bit for bit, and is not counted as moved.
        if ((target - x).norm() <=
            kRoundOffMove * (local_edge_length_[v] + x.lpNorm<Eigen::Infinity>()))
          target = x;
        if (!target.allFinite() || (bounded && (target - x).norm() > bound) ||
            !keeps_orientation(v, to_vec3(target)))
          continue;
        mesh_.positions[v] = to_vec3(target);
        settled[v] = 1;
        used_primitive_count[v] = static_cast<std::uint32_t>(count);
        changed = true;
        break;
      }
    }
    if (!changed && !last_sweep) sweep = kSweeps - 2;  // nothing more to gain: fall back now
  }

  for (std::uint32_t v = 0; v < n; ++v) {
    if (settled[v] == 2) continue;
    if (!settled[v]) {
      ++report.blocked;
      continue;
    }
    ++report.snapped;
    if (used_primitive_count[v] < incident_count[v] && options_.mode == SnapMode::AllIncident)
      ++report.fallbacks;
  }
  measure_moves(start, mesh_.positions, report);
  return report;
}

Mesh denoise(const Mesh& mesh, const LevelSelector& level, const DenoiseOptions& options,
             int iterations) {
  if (iterations < 1) throw InvalidInputError("denoise: iterations must be at least 1");
  Denoiser denoiser(mesh, options);
  for (int i = 0; i < iterations; ++i) denoiser.iterate(level);
  return denoiser.mesh();
}

}  // namespace primseg
