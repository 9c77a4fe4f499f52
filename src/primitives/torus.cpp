// Torus: from the cluster's bounded corner sample (ClusterStats::samples, at most 32 corners with
// their faces' normals and centroids), so a candidate costs the same for any cluster size.
//
// 1. Axis: every normal line of a surface of revolution meets its axis. A line (d, m) in Plücker
//    coordinates meets the axis (a, p × a) iff d·(p × a) + a·m = 0, linear in (a, p × a): the
//    weighted least squares over the samples' normal lines, with |a| = 1, is a 3×3 eigenproblem
//    once p × a is eliminated. Coplanar normals (a cylinder, a plane) leave it undetermined.
//    The normal lines of a narrow wedge of a torus also nearly meet the tangent of its centre
//    circle, about which the wedge is a cylinder: when the best direction is along the one the
//    normals have least of and gives no tube's circle, the best direction across it is tried,
//    for an exact torus only.
// 2. Profile: in the half-plane through the axis, (ρ, h) = (distance to the axis, height) of the
//    samples lie on the tube's circle: Pratt's circle fit gives the major radius (its centre's
//    ρ), the centre's height and the minor radius.
// 3. A few Levenberg–Marquardt steps of the true Euclidean distance (geometric_fit.hpp) over the
//    samples, so that points exactly on a torus give it exactly.
// The sample of a candidate union is stratified: each of its two clusters contributes its own
// priority sample, at least half of the 32 corners unless it has fewer (draw_sample). A union's
// own sample is the best 32 priorities of both, which often holds none of a small part's corners:
// four faces off the surface added to a torus of 526 faces went unseen, at a sampled RMS of 1.5e-6
// against 0.0079 for a torus fitted to all 531 (rotor.off of libcgal-demo).
// The error is the priority-sampling estimate of Σ w d² (estimator weights max(w, τ), see
// SampleReservoir, summed over the strata), normalised to the cluster's exact weight; when the
// sample is not the whole cluster it is scaled by n / (n − 7), the usual correction for the 7
// parameters fitted to the same n points, and raised when the sample lies closer to the cluster's
// principal plane than the cluster does (lucky_sample_factor). It is a first-order L2 like the
// other types', but a sampled one: its relative noise is about 1/sqrt(32) for large clusters.
#include "primseg/primitives/torus.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <span>
#include <utility>

#include "eigen_conversions.hpp"
#include "primitives/pratt_fit.hpp"
#include "primseg/geometric_fit.hpp"
#include "symmetric_eigen3.hpp"

namespace primseg {
namespace {

constexpr int kParameters = 7;
// The smallest eigenvalue of Σ ŵ n nᵀ over Σ ŵ below this: normals (nearly) coplanar, no torus.
constexpr double kTorusMinNormalSpread = 1e-9;
// Largest minor radius, relative to the RMS spread of the cluster: a wider tube bends the cluster
// by less than a fortieth of its size across, and the torus is standing in for a cone, a
// cylinder or a plane (a cone's band is fitted by tori of growing tube as closely as wanted).
constexpr double kMaxRelativeMinorRadius = 20;
// Smallest determinant of the profile's weighted second moment over its squared trace (about the
// ratio of its two principal spreads, squared lengths): below it the profile points lie on a line
// to within 1e-6 of their extent.
constexpr double kMinProfileDeterminant = 1e-12;
// |cos| of the angle between the best axis direction and the normals' least direction from
// which the best direction may be a wedge's cylinder axis (25 degrees).
constexpr double kAlongLeastNormal = 0.9;
// RMS distance of an exact torus to its sample, in units of the cluster's RMS spread: its Σ w d²
// is then below 1e-12 of the spread, the level at which costs snap to zero by default.
constexpr double kExactRms = 1e-6;
// Levenberg–Marquardt steps on the sample (each O(32)).
constexpr int kTorusRefinementSteps = 8;

// The cluster's corner sample about its centroid, in units of its RMS spread (fixed capacity:
// this runs for every candidate merge).
struct TorusSample {
  static constexpr std::size_t kCapacity = SampleReservoir::kCapacity;
  std::size_t n = 0;
  std::array<Vec3, kCapacity> points;
  std::array<double, kCapacity> weights;  // the estimator weights
  std::array<Eigen::Vector3d, kCapacity> positions, normals;
  std::array<Eigen::Vector3d, kCapacity> to_centroids;  // the face's centroid − the corner
  double weight = 0;                                    // Σ of the estimator weights
  bool whole = true;  // every corner of the cluster is in (exact sums)
};

// Draws the sample of a cluster whose corner samples come in `strata` (ClusterView::
// sample_strata), about `origin` in units of 1 / scale. One stratum: its estimate as it is. Two:
// each stratum's highest priorities, k of them, with estimator weights max(w, τ_k)
// (SampleReservoir::threshold(k)); the
// first stratum gets at least half of the capacity, or all of its corners when it has fewer, and
// the second the rest, so that neither part of a union goes unseen.
void draw_sample(const std::array<const SampleReservoir*, 2>& strata, const Eigen::Vector3d& origin,
                 double scale, TorusSample& sample) {
  std::array<std::size_t, 2> taken = {strata[0]->estimate_size(), 0};
  if (strata[1]) {
    const std::size_t half = TorusSample::kCapacity / 2;
    const std::size_t second = strata[1]->estimate_size();
    taken[0] = std::min(taken[0], std::max(half, TorusSample::kCapacity - second));
    taken[1] = std::min(second, TorusSample::kCapacity - taken[0]);
  }
  sample.n = 0;
  sample.weight = 0;
  sample.whole = true;
  for (int s = 0; s < 2 && strata[s]; ++s) {
    const std::vector<SurfaceSample>& corners = strata[s]->samples;
    const double threshold = strata[s]->threshold(taken[s]);
    if (threshold > 0) sample.whole = false;
    for (std::size_t i = 0; i < taken[s]; ++i, ++sample.n) {
      const SurfaceSample& corner = corners[i];
      const std::size_t j = sample.n;
      sample.positions[j] = (corner.position - origin) * scale;
      sample.normals[j] = corner.normal.cast<double>();
      sample.to_centroids[j] = corner.to_centroid.cast<double>() * scale;
      sample.weights[j] = std::max(corner.weight, threshold);
      sample.points[j] = {sample.positions[j].x(), sample.positions[j].y(),
                          sample.positions[j].z()};
      sample.weight += sample.weights[j];
    }
  }
}

// The normal lines' least squares over the axis (a, p × a), p × a eliminated: a's quadratic form
// `reduced`, and how the moment follows from a. Nothing when the normals are (nearly) coplanar.
// Each face's normal line is drawn through the sampled corner (axis_problem) or through its
// face's centroid (through_centroids).
struct AxisProblem {
  Eigen::Matrix3d reduced;
  Eigen::Matrix3d nn_inverse, cross_block;
  // The direction the normals have least of (the smallest eigenvector of Σ ŵ n nᵀ): on a narrow
  // wedge of a torus, the tangent of its centre circle.
  Eigen::Vector3d least_normal;
};

// The lines' part of `problem`, for normal lines through point(i); the normals' part (nn_inverse,
// least_normal) is the same wherever the lines are drawn through.
template <typename Point>
void set_lines(const TorusSample& sample, const Point& point, AxisProblem& problem) {
  Eigen::Matrix3d moments = Eigen::Matrix3d::Zero(), cross = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < sample.n; ++i) {
    const Eigen::Vector3d moment = point(i).cross(sample.normals[i]);
    const Eigen::Vector3d weighted = sample.weights[i] * moment;
    moments.noalias() += weighted * moment.transpose();
    cross.noalias() += weighted * sample.normals[i].transpose();
  }
  problem.cross_block = cross;
  problem.reduced = moments - cross * problem.nn_inverse * cross.transpose();
}

std::optional<AxisProblem> axis_problem(const TorusSample& sample) {
  Eigen::Matrix3d nn = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < sample.n; ++i)
    nn.noalias() += (sample.weights[i] * sample.normals[i]) * sample.normals[i].transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> normal_eigen(nn);
  if (!(normal_eigen.eigenvalues()(0) > kTorusMinNormalSpread * sample.weight)) return std::nullopt;
  AxisProblem problem;
  problem.nn_inverse = normal_eigen.eigenvectors() *
                       normal_eigen.eigenvalues().cwiseInverse().asDiagonal() *
                       normal_eigen.eigenvectors().transpose();
  problem.least_normal = normal_eigen.eigenvectors().col(0);
  set_lines(
      sample, [&](std::size_t i) { return sample.positions[i]; }, problem);
  return problem;
}

// `problem` with the normal lines through the faces' centroids instead of the corners.
AxisProblem through_centroids(const TorusSample& sample, AxisProblem problem) {
  set_lines(
      sample,
      [&](std::size_t i) -> Eigen::Vector3d {
        return sample.positions[i] + sample.to_centroids[i];
      },
      problem);
  return problem;
}

// The axis line with direction `axis` that the normal lines meet best: (axis, its point nearest
// the centroid).
std::pair<Eigen::Vector3d, Eigen::Vector3d> axis_line(const AxisProblem& problem,
                                                      const Eigen::Vector3d& axis) {
  Eigen::Vector3d moment = -problem.nn_inverse * problem.cross_block.transpose() * axis;
  moment -= axis * axis.dot(moment);  // a Plücker line: moment ⊥ direction
  return {axis, axis.cross(moment)};
}

// The best direction: the smallest eigenvector of the reduced form.
Eigen::Vector3d best_axis(const AxisProblem& problem) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(problem.reduced);
  return eigen.eigenvectors().col(0).normalized();
}

// The best direction across the normals' least direction t (a ⊥ t). Every normal line of a
// narrow wedge of a torus also meets the tangent of its centre circle, nearly as well as the
// axis: the best direction may then be that tangent (about which the wedge is a cylinder, not a
// torus), and the axis is the best direction across it.
Eigen::Vector3d best_axis_across_least_normal(const AxisProblem& problem) {
  const Eigen::Vector3d& t = problem.least_normal;
  const Eigen::Vector3d u = t.unitOrthogonal(), v = t.cross(u);
  Eigen::Matrix<double, 3, 2> basis;
  basis << u, v;
  const Eigen::Matrix2d form = basis.transpose() * problem.reduced * basis;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(form);
  return (basis * eigen.eigenvectors().col(0)).normalized();
}

// The samples in the half-plane through the axis (`axis` through `on_axis`): (ρ, h) = (distance
// to the axis, height along it), their weighted mean and their weighted second moment about it.
struct SampleProfile {
  std::array<Eigen::Vector2d, TorusSample::kCapacity> rho_h;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
};

SampleProfile profile_of(const TorusSample& sample, const Eigen::Vector3d& axis,
                         const Eigen::Vector3d& on_axis) {
  SampleProfile profile;
  for (std::size_t i = 0; i < sample.n; ++i) {
    const Eigen::Vector3d y = sample.positions[i] - on_axis;
    const double h = axis.dot(y);
    profile.rho_h[i] = {(y - h * axis).norm(), h};
    profile.mean += sample.weights[i] * profile.rho_h[i];
  }
  profile.mean /= sample.weight;
  for (std::size_t i = 0; i < sample.n; ++i) {
    const Eigen::Vector2d p = profile.rho_h[i] - profile.mean;
    profile.second.noalias() += sample.weights[i] * p * p.transpose();
  }
  return profile;
}

// The tube's circle in the (ρ, h) half-plane of the axis through `on_axis`: its centre (ρ, h)
// and radius. Nothing when Pratt's fit fails or the centre is not off the axis.
std::optional<std::pair<Eigen::Vector2d, double>> tube_circle(const TorusSample& sample,
                                                              const Eigen::Vector3d& axis,
                                                              const Eigen::Vector3d& on_axis) {
  const SampleProfile profile = profile_of(sample, axis, on_axis);
  detail::CentredMomentsND<2> moments;
  moments.weight = sample.weight;
  moments.second = profile.second;
  moments.third.setZero();
  for (std::size_t i = 0; i < sample.n; ++i) {
    const Eigen::Vector2d p = profile.rho_h[i] - profile.mean;
    moments.third += sample.weights[i] * p * p.squaredNorm();
    moments.fourth += sample.weights[i] * p.squaredNorm() * p.squaredNorm();
  }
  const detail::PrattResult<2> circle = detail::pratt_fit(moments);
  if (!circle.valid) return std::nullopt;
  const Eigen::Vector2d tube_centre = profile.mean + circle.centre;
  if (!(tube_centre.x() > 0)) return std::nullopt;  // the centre circle must have a radius
  return std::pair{tube_centre, circle.radius};
}

// Whether the samples' profile about the torus's axis determines the tube's circle. Corners on
// at most two rings (a CAD cone, or a fan and a cone between two circles) put it on a line or on
// two points, through which a whole family of circles passes: any of them fits exactly, and the
// one a fit lands on is arbitrary. A cone or a plane fits such a band.
bool profile_determines_tube(const Primitive& torus, const TorusSample& sample) {
  const Eigen::Matrix2d second =
      profile_of(sample, detail::to_eigen(torus.axis), detail::to_eigen(torus.point)).second;
  const double trace = second.trace();
  return second.determinant() > kMinProfileDeterminant * trace * trace;
}

// Face normals must follow the torus's across each face: mean |n · ν| over the sample, ν the
// torus's normal at the point nearest the corner, and again nearest the face's centroid (where
// the cylinder and sphere compare them); the lower mean counts. The corners alone are not
// enough: the vertices of a flat cap's fan all lie on the torus's top circle, where its normal
// is the cap's, yet the faces between them leave the torus.
double torus_normal_alignment(const Primitive& torus, const TorusSample& sample) {
  const Eigen::Vector3d torus_centre = detail::to_eigen(torus.point);
  const Eigen::Vector3d torus_axis = detail::to_eigen(torus.axis);
  // |f · ν(x)| for the face normal f, 0 on the axis (no normal, no agreement).
  auto agreement = [&](const Eigen::Vector3d& x, const Eigen::Vector3d& face_normal) {
    const Eigen::Vector3d y = x - torus_centre;
    const Eigen::Vector3d radial = y - torus_axis * torus_axis.dot(y);
    if (!(radial.squaredNorm() > 0)) return 0.0;
    const Eigen::Vector3d nearest = detail::to_eigen(torus.closest_point(detail::to_vec3(x)));
    const Eigen::Vector3d ring = torus_centre + radial.normalized() * torus.radius;
    const Eigen::Vector3d normal = (nearest - ring).normalized();
    return std::abs(normal.dot(face_normal));
  };
  double at_corners = 0, at_centroids = 0;
  for (std::size_t i = 0; i < sample.n; ++i) {
    at_corners += sample.weights[i] * agreement(sample.positions[i], sample.normals[i]);
    const Eigen::Vector3d centroid = sample.positions[i] + sample.to_centroids[i];
    at_centroids += sample.weights[i] * agreement(centroid, sample.normals[i]);
  }
  return std::min(at_corners, at_centroids) / sample.weight;
}

// How lucky the sample is: the whole cluster's mean squared distance to its principal plane (the
// smallest eigenvalue of the centred second moment, over its trace: exact, in units of the
// spread) over the sample's estimate of it, when that is above 1; else 1. The merge loop keeps
// whichever evaluation of a cluster came out lowest, and a torus fitted to 32 corners that happen
// to lie closer to the plane than the cluster does fits them too well: a noisy flat face's torus
// came out at half its plane's exact error and won despite its penalty of 2 (the noisy box of
// `primseg eval` with tori enabled). On noise, the distances to the torus and to the plane rise
// and fall together from sample to sample, so the torus's error is raised in the same ratio. An
// unlucky sample is not lowered: on a curved cluster the plane's distances are its smooth misfit,
// unrelated to the torus's residuals, and lowering would let a torus win by chance there.
double lucky_sample_factor(const Moments& centred, const TorusSample& sample) {
  const Eigen::Matrix3d second_moment = centred.second_moment();
  const detail::Eigenpair plane = detail::smallest_eigenpair(second_moment);
  double sampled = 0;  // Σ ŵ (n·y)² / Σ ŵ
  for (std::size_t i = 0; i < sample.n; ++i) {
    const double distance = plane.vector.dot(sample.positions[i]);
    sampled += sample.weights[i] * (distance * distance);
  }
  sampled /= sample.weight;
  const double exact = plane.value / second_moment.trace();
  return exact > sampled && sampled > 0 && std::isfinite(exact) ? exact / sampled : 1;
}

// The second try, across the normals' least direction, takes exact tori only. Its start is
// rougher than the first try's (the face normals' lines meet the axis less well on a narrow
// wedge), so it may take up to kExactTorusSteps Levenberg–Marquardt steps; after the first
// kExactProbeSteps the RMS distance to the sample must be within kExactProbeRms (spread units),
// where LM's progress on points off every torus stalls. The probe keeps the cost of those steps
// off clusters on no torus (most second tries are unions of two surfaces): over `primseg eval
// --seeds 3` with five types, 3% of the uniform shapes' 160,288 second tries and none of the noisy
// ones' pass it (docs/method.md).
constexpr int kExactTorusSteps = 16;
constexpr int kExactProbeSteps = 2;
constexpr double kExactProbeRms = 1e-2;

// A fit about one axis line, and whether the samples' profile about it gave a tube's circle.
struct AxisFit {
  PrimitiveFit fit;
  bool tube = false;
};

// Steps 2 and 3 and the validity rules, about the axis line (`axis`, through `on_axis`, sample
// units); with `exact_only`, a torus farther than kExactRms from the sample is not valid.
AxisFit fit_about_axis(const TorusSample& sample, const Moments& m, double scale,
                       const Eigen::Vector3d& axis, const Eigen::Vector3d& on_axis,
                       bool exact_only) {
  AxisFit about;
  PrimitiveFit& result = about.fit;
  result.primitive.type = PrimitiveType::Torus;
  const auto tube = tube_circle(sample, axis, on_axis);
  if (!tube) return about;
  about.tube = true;
  const auto& [tube_centre, tube_radius] = *tube;

  Primitive start;
  start.type = PrimitiveType::Torus;
  const Eigen::Vector3d centre = on_axis + tube_centre.y() * axis;
  start.point = {centre.x(), centre.y(), centre.z()};
  start.axis = {axis.x(), axis.y(), axis.z()};
  start.radius = tube_centre.x();
  start.minor_radius = tube_radius;
  const std::size_t n = sample.n;
  const std::span<const Vec3> points(sample.points.data(), n);
  const std::span<const double> weights(sample.weights.data(), n);
  GeometricFitOptions options;
  GeometricFit refined;
  if (exact_only) {
    options.max_iterations = kExactProbeSteps;
    refined = fit_geometric(start, points, weights, options);
    if (!(refined.rms <= kExactProbeRms)) return about;
    options.max_iterations = kExactTorusSteps - kExactProbeSteps;
    refined = fit_geometric(refined.primitive, points, weights, options);
    if (!(refined.rms <= kExactRms)) return about;
  } else {
    options.max_iterations = kTorusRefinementSteps;
    refined = fit_geometric(start, points, weights, options);
  }
  const Primitive& torus = refined.primitive;
  if (!(torus.minor_radius > 0) || torus_ring_vanishes(torus) ||
      !(torus.radius <= detail::kMaxRelativeRadius &&
        torus.minor_radius <= kMaxRelativeMinorRadius))
    return about;
  if (!profile_determines_tube(torus, sample)) return about;
  result.normal_alignment = torus_normal_alignment(torus, sample);
  if (!(result.normal_alignment >= kMinNormalAlignment)) return about;

  const double weight = m.weight(), spread2 = m.second_moment().trace() / weight;
  double error = refined.rms * refined.rms * weight;  // refined.rms: Σ ŵ d² / Σ ŵ
  if (!sample.whole) error *= double(n) / double(n - kParameters) * lucky_sample_factor(m, sample);
  result.valid = true;
  result.error = error * spread2;
  const Eigen::Vector3d input_centre = m.origin() + detail::to_eigen(torus.point) / scale;
  result.primitive = torus;
  const Eigen::Vector3d canonical = canonical_axis(detail::to_eigen(torus.axis));
  result.primitive.axis = {canonical.x(), canonical.y(), canonical.z()};
  result.primitive.point = {input_centre.x(), input_centre.y(), input_centre.z()};
  result.primitive.radius = torus.radius / scale;
  result.primitive.minor_radius = torus.minor_radius / scale;
  return about;
}

}  // namespace

std::uint32_t TorusFitter::min_triangles() const {
  return 8;
}

PrimitiveFit TorusFitter::fit(const ClusterView& cluster, double /*error_to_beat*/) const {
  const ClusterStats& centred = cluster.stats();
  PrimitiveFit result;
  result.primitive.type = PrimitiveType::Torus;
  const Moments& m = centred.moments;
  const double weight = m.weight();
  if (centred.triangle_count < min_triangles() || !(weight > 0)) return result;
  const double spread2 = m.second_moment().trace() / weight;
  if (!(spread2 > 0) || !std::isfinite(spread2)) return result;
  const double scale = 1 / std::sqrt(spread2);

  TorusSample sample;
  draw_sample(cluster.sample_strata(), m.origin(), scale, sample);
  if (sample.n <= kParameters + 1 || !(sample.weight > 0)) return result;

  // 1. The axis; 2. the tube's circle; 3. geometric refinement on the sample.
  const std::optional<AxisProblem> problem = axis_problem(sample);
  if (!problem) return result;
  const Eigen::Vector3d first = best_axis(*problem);
  const auto [axis, on_axis] = axis_line(*problem, first);
  const AxisFit about_first = fit_about_axis(sample, m, scale, axis, on_axis, false);
  // No tube's circle about a best direction along the normals' least one: on a narrow wedge of
  // an exact torus (the first faces of a CAD fillet, up to about 70 degrees round with 48
  // segments) that is the wedge's own cylinder axis, about which its profile is a short line, and
  // the torus's axis is the best direction across it. Only an exact torus counts there: about a
  // direction across a noisy cylinder's axis, a torus of wide ring fits the cylinder, and its
  // sampled error would win by chance. The face's normal is nearer the surface's at its centroid
  // than at its corners, and the lines through the centroids give a better axis across (on 12-row
  // quarter tubes of 1 to 9 segments, 1 to 11 degrees off on 8 of 9, docs/method.md); the lines
  // through the corners give the sampled fits the balance with the other types they were set on.
  if (about_first.tube || !(std::abs(first.dot(problem->least_normal)) >= kAlongLeastNormal))
    return about_first.fit;
  const AxisProblem across = through_centroids(sample, *problem);
  const Eigen::Vector3d second = best_axis_across_least_normal(across);
  const auto [second_axis, second_on_axis] = axis_line(across, second);
  return fit_about_axis(sample, m, scale, second_axis, second_on_axis, true).fit;
}

}  // namespace primseg
