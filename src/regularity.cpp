#include "regularity.hpp"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <queue>
#include <span>
#include <tuple>
#include <utility>

#include "eigen_conversions.hpp"
#include "orthonormal_pair.hpp"
#include "regularity_shared.hpp"

namespace primseg::detail {

bool within_tolerance(double size, double tolerance) {
  return tolerance > 0 && size <= tolerance;
}

double tolerated(double score, double bound, double size, double tolerance) {
  if (!(tolerance > 0)) return score;
  const double scaled = size / tolerance;
  return std::min(score, bound * scaled * scaled);
}

double chi_square_bound(double significance, std::size_t freedom) {
  if (freedom == 1) return significance * significance;
  const double tail = std::erfc(significance / std::numbers::sqrt2);
  if (freedom == 2) return -2 * std::log(tail);
  const double k = static_cast<double>(freedom), spread = 2 / (9 * k);
  return k * std::pow(1 - spread + significance * std::sqrt(spread), 3);
}

double residual_excess(double own_rms, double joint_rms, std::size_t count, double significance2,
                       int parameters, double length_tolerance) {
  const double n = static_cast<double>(count);
  const double rise = n * (joint_rms * joint_rms - own_rms * own_rms);
  return tolerated(rise / (significance2 * own_rms * own_rms * n / (n - parameters)), 1,
                   std::sqrt(std::max(rise / n, 0.0)), length_tolerance);
}

void place_cylinder(Primitive& cylinder, const Eigen::Vector3d& direction,
                    const Eigen::Vector2d& centre, double radius) {
  const auto [u, v] = orthonormal_pair(direction);
  cylinder.axis = to_vec3(direction.dot(to_eigen(cylinder.axis)) < 0 ? -direction : direction);
  const Eigen::Vector3d on_axis = centre.x() * u + centre.y() * v;
  cylinder.point = to_vec3(on_axis + direction * direction.dot(to_eigen(cylinder.point) - on_axis));
  cylinder.radius = radius;
}

namespace {

// Two directions the right angles made one, to round-off (radians).
constexpr double kSameDirection = 1e-12;

// A primitive with a direction (a plane's normal, a cylinder's axis) and how well its inliers
// determine it.
struct Oriented {
  std::size_t cluster = 0;
  Eigen::Vector3d direction;
  double variance = 0;  // of its tilt, radians², in the worst direction
  // Covariance of the tilt (radians²) along the tangent directions `frame` (columns).
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  Eigen::Matrix<double, 3, 2> frame;
};

// An item's information about its group's direction: Fᵢ Cᵢ⁻¹ Fᵢᵀ.
Eigen::Matrix3d direction_information(const Oriented& item) {
  return item.frame * item.covariance.inverse() * item.frame.transpose();
}

// The covariance of a direction's tilt from the eigen-decomposition of its information: the
// inverse across it, over the two largest eigenvalues (the direction is the smallest's).
Eigen::Matrix3d tilt_covariance(const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>& eigen) {
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int k = 1; k < 3; ++k)
    covariance += eigen.eigenvectors().col(k) * eigen.eigenvectors().col(k).transpose() /
                  eigen.eigenvalues()(k);
  return covariance;
}

// The group's direction and its covariance, from its information.
void form_direction(DirectionGroup& group) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(group.information);
  group.direction = eigen.eigenvectors().col(0);
  group.covariance = tilt_covariance(eigen);
}

double angle_between_lines(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

std::optional<Oriented> oriented_plane(std::size_t cluster, std::span<const Vec3> points) {
  const std::size_t n = points.size();
  if (n < 6) return std::nullopt;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Vec3& p : points) centroid += to_eigen(p);
  centroid /= static_cast<double>(n);
  Oriented item;
  item.cluster = cluster;
  // The unweighted least-squares plane's: its tilt has variance σ̂²/λ along each in-plane
  // eigenvector of the scatter S (eigenvalue λ), and Σ Fᵢ Cᵢ⁻¹ Fᵢᵀ over a group of planes is their
  // summed scatter (less the residual terms), whose smallest eigenvector is their joint normal.
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Vec3& p : points) {
    const Eigen::Vector3d e = to_eigen(p) - centroid;
    scatter += e * e.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  item.direction = eigen.eigenvectors().col(0);
  const double extent2 = std::max(eigen.eigenvalues()(2), 0.0) / double(n);
  const double residual_variance = std::max(std::max(eigen.eigenvalues()(0), 0.0) / double(n - 3),
                                            kResolution * kResolution * extent2);
  if (!(eigen.eigenvalues()(1) > 0)) return std::nullopt;
  item.frame.col(0) = eigen.eigenvectors().col(1);
  item.frame.col(1) = eigen.eigenvectors().col(2);
  item.covariance = Eigen::Vector2d(residual_variance / eigen.eigenvalues()(1),
                                    residual_variance / eigen.eigenvalues()(2))
                        .asDiagonal();
  item.variance = item.covariance(0, 0);
  return item;
}

std::optional<Oriented> oriented_cylinder(std::size_t cluster, const Primitive& cylinder,
                                          std::span<const Vec3> points) {
  const std::size_t n = points.size();
  if (n < 12) return std::nullopt;
  Oriented item;
  item.cluster = cluster;
  const Eigen::Vector3d a = to_eigen(cylinder.axis).normalized(), p = to_eigen(cylinder.point);
  const auto [u, v] = orthonormal_pair(a);
  item.direction = a;
  item.frame.col(0) = u;
  item.frame.col(1) = v;
  // Information of the parameters (tilt along u and v times the radius, so that every column is
  // in the same units and the result does not depend on them; shift of the axis along u and v;
  // radius) from the residuals' Jacobian: e = |Q(x − p)| − r, Q = I − a aᵀ.
  const double radius = cylinder.radius;
  if (!(radius > 0)) return std::nullopt;
  Eigen::Matrix<double, 5, 5> information = Eigen::Matrix<double, 5, 5>::Zero();
  double residuals = 0;
  for (const Vec3& point : points) {
    const Eigen::Vector3d d = to_eigen(point) - p;
    const double t = a.dot(d);
    const Eigen::Vector3d radial = d - t * a;
    const double length = radial.norm();
    if (!(length > 0)) continue;
    const Eigen::Vector3d normal = radial / length;
    const double e = length - radius;
    residuals += e * e;
    Eigen::Matrix<double, 5, 1> j;
    j << -t / radius * normal.dot(u), -t / radius * normal.dot(v), -normal.dot(u), -normal.dot(v),
        -1;
    information += j * j.transpose();
  }
  const Eigen::Matrix<double, 5, 5> covariance =
      information.inverse() *
      std::max(residuals / double(n - 5), kResolution * kResolution * radius * radius);
  if (!covariance.allFinite()) return std::nullopt;
  item.covariance = covariance.topLeftCorner<2, 2>() / (radius * radius);
  item.variance = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(item.covariance).eigenvalues()(1);
  return item;
}

// One cylinder of a joint fit: its inliers, and the axis line and the radius it takes (indices
// into the fit's lines and radii).
struct CylinderTerm {
  std::span<const Vec3> points;
  std::span<const double> weights;
  std::size_t line = 0;
  std::size_t radius = 0;
};

// No line: the `line` of a sphere (a joint fit's term, a settled surface) whose centre is its own.
constexpr std::size_t kNoLine = std::numeric_limits<std::size_t>::max();

// A sphere's points: sphere s of a joint fit has one of its radii, and its own centre, or its
// centre on one of its lines (one parameter along it).
struct SphereTerm {
  std::span<const Vec3> points;
  std::span<const double> weights;
  std::size_t radius = 0;
  std::size_t line = kNoLine;
};

// Axis lines of fixed directions, sphere centres and radii fitted together by geometric least
// squares: each cylinder term's residuals are its points' distances to its line minus its radius,
// each sphere's their distances to its centre minus its radius. Several terms on one line are
// coaxial cylinders (and spheres centred on their axis); several on one radius, cylinders (and
// spheres) of equal radius.
struct JointFit {
  std::vector<Eigen::Vector2d> centres;  // per line, in orthonormal_pair(direction) coordinates
  std::vector<Eigen::Vector3d> sphere_centres;
  std::vector<double> radii;
  // Per cylinder term, then per sphere; unweighted, at least kResolution × the radius.
  std::vector<double> rms;
  // Of (line centres, free sphere centres, the positions along their lines of the spheres on
  // one, radii), from the unweighted residuals (if asked).
  Eigen::MatrixXd covariance;
};

// Gauss–Newton from `centres`, `sphere_centres` and `radii` (weighted steps; the uncertainty,
// when asked for, from the unweighted residuals at the solution); a sphere on a line starts from
// its centre's projection onto it. Nothing when it diverges, a radius ends non-positive or the
// points do not outnumber the parameters. A step of one line and no sphere solves the normal
// equations whole; otherwise it eliminates each line's and each free sphere's position first (a
// 2x2 or 3x3 block that couples only to its own terms' radii; a sphere on a line, its position
// along it before the line's), so that a plate of n holes of one radius costs O(n), not O(n³).
std::optional<JointFit> fit_cylinders_and_spheres(std::span<const Eigen::Vector3d> directions,
                                                  std::span<const Eigen::Vector2d> centres,
                                                  std::span<const Eigen::Vector3d> sphere_centres,
                                                  std::span<const double> radii,
                                                  std::span<const CylinderTerm> terms,
                                                  std::span<const SphereTerm> spheres,
                                                  bool with_covariance) {
  const Eigen::Index lines = static_cast<Eigen::Index>(centres.size());
  const Eigen::Index sphere_count = static_cast<Eigen::Index>(spheres.size());
  const Eigen::Index radius_count = static_cast<Eigen::Index>(radii.size());
  // x = (line centres 2 each, free sphere centres 3 each, positions of the spheres on a line along
  // it, radii).
  const Eigen::Index free_spheres = std::count_if(
      spheres.begin(), spheres.end(), [](const SphereTerm& s) { return s.line == kNoLine; });
  std::vector<Eigen::Index> sphere_offset(spheres.size());
  Eigen::Index next_free = 2 * lines, next_on_line = 2 * lines + 3 * free_spheres;
  for (std::size_t s = 0; s < spheres.size(); ++s)
    sphere_offset[s] =
        spheres[s].line == kNoLine ? std::exchange(next_free, next_free + 3) : next_on_line++;
  const Eigen::Index first_radius = next_on_line;
  const Eigen::Index size = first_radius + radius_count;
  Eigen::VectorXd x(size);
  for (Eigen::Index l = 0; l < lines; ++l) x.segment<2>(2 * l) = centres[l];
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    if (spheres[s].line == kNoLine)
      x.segment<3>(sphere_offset[s]) = sphere_centres[s];
    else
      x(sphere_offset[s]) = directions[spheres[s].line].dot(sphere_centres[s]);
  }
  for (Eigen::Index q = 0; q < radius_count; ++q) x(first_radius + q) = radii[q];
  // The points in the plane orthogonal to their line's direction, once for every iteration; a
  // sphere's on a line in its frame (u, v, direction).
  std::vector<std::vector<Eigen::Vector2d>> projected(terms.size());
  std::vector<std::vector<std::size_t>> terms_on_line(centres.size()),
      spheres_on_line(centres.size());
  for (std::size_t k = 0; k < terms.size(); ++k) {
    const auto [u, v] = orthonormal_pair(directions[terms[k].line]);
    for (const Vec3& p : terms[k].points)
      projected[k].emplace_back(u.dot(to_eigen(p)), v.dot(to_eigen(p)));
    terms_on_line[terms[k].line].push_back(k);
  }
  std::vector<std::vector<Eigen::Vector3d>> sphere_local(spheres.size());
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    const std::size_t l = spheres[s].line;
    if (l == kNoLine) continue;
    const Eigen::Vector3d& direction = directions[l];
    const auto [u, v] = orthonormal_pair(direction);
    for (const Vec3& p : spheres[s].points)
      sphere_local[s].emplace_back(u.dot(to_eigen(p)), v.dot(to_eigen(p)),
                                   direction.dot(to_eigen(p)));
    spheres_on_line[l].push_back(s);
  }
  // The normal equations by blocks: each line's own 2x2, each term's coupling of its line and its
  // radius, each radius's diagonal (radii never couple with each other, lines never with lines).
  // A sphere's 3x3 block is over its centre, or over its line's centre and its position along it.
  std::vector<Eigen::Matrix2d> line_block(centres.size());
  std::vector<Eigen::Vector2d> coupling(terms.size()), line_gradient(centres.size());
  std::vector<Eigen::Matrix3d> sphere_block(spheres.size());
  std::vector<Eigen::Vector3d> sphere_coupling(spheres.size()), sphere_gradient(spheres.size());
  Eigen::VectorXd radius_diagonal(radius_count), radius_gradient(radius_count);
  // Per cylinder term, then per sphere.
  std::vector<double> term_squares(terms.size() + spheres.size());
  std::vector<std::size_t> term_count(terms.size() + spheres.size());
  std::size_t count = 0;
  auto linearise = [&](bool weighted) {
    std::fill(line_block.begin(), line_block.end(), Eigen::Matrix2d::Zero());
    std::fill(coupling.begin(), coupling.end(), Eigen::Vector2d::Zero());
    std::fill(line_gradient.begin(), line_gradient.end(), Eigen::Vector2d::Zero());
    std::fill(sphere_block.begin(), sphere_block.end(), Eigen::Matrix3d::Zero());
    std::fill(sphere_coupling.begin(), sphere_coupling.end(), Eigen::Vector3d::Zero());
    std::fill(sphere_gradient.begin(), sphere_gradient.end(), Eigen::Vector3d::Zero());
    radius_diagonal.setZero();
    radius_gradient.setZero();
    double squares = 0;
    count = 0;
    // A point's residual |d| − radius (d from the centre: in the line's plane, or in space for a
    // sphere) added to its position's block, coupling and gradient, its radius's, and term k's.
    auto add_point = [&](const auto& d, double radius, double w, auto& block, auto& term_coupling,
                         auto& position_gradient, Eigen::Index q, std::size_t k) {
      const double length = d.norm();
      if (!(length > 0)) return;
      const double e = length - radius;
      const auto j = (-d / length).eval();
      block += w * j * j.transpose();
      term_coupling -= w * j;
      radius_diagonal(q) += w;
      position_gradient += w * j * e;
      radius_gradient(q) -= w * e;
      squares += e * e;
      term_squares[k] += e * e;
      ++term_count[k];
      ++count;
    };
    for (std::size_t k = 0; k < terms.size(); ++k) {
      const std::size_t l = terms[k].line;
      const Eigen::Index q = static_cast<Eigen::Index>(terms[k].radius);
      const Eigen::Vector2d centre = x.segment<2>(2 * static_cast<Eigen::Index>(l));
      const double radius = x(first_radius + q);
      term_squares[k] = 0;
      term_count[k] = 0;
      for (std::size_t i = 0; i < projected[k].size(); ++i)
        add_point((projected[k][i] - centre).eval(), radius, weighted ? terms[k].weights[i] : 1.0,
                  line_block[l], coupling[k], line_gradient[l], q, k);
    }
    for (std::size_t s = 0; s < spheres.size(); ++s) {
      const Eigen::Index q = static_cast<Eigen::Index>(spheres[s].radius);
      const Eigen::Index offset = sphere_offset[s];
      const double radius = x(first_radius + q);
      const std::size_t k = terms.size() + s;
      term_squares[k] = 0;
      term_count[k] = 0;
      if (spheres[s].line == kNoLine) {
        const Eigen::Vector3d centre = x.segment<3>(offset);
        for (std::size_t i = 0; i < spheres[s].points.size(); ++i)
          add_point((to_eigen(spheres[s].points[i]) - centre).eval(), radius,
                    weighted ? spheres[s].weights[i] : 1.0, sphere_block[s], sphere_coupling[s],
                    sphere_gradient[s], q, k);
      } else {
        const Eigen::Index l = 2 * static_cast<Eigen::Index>(spheres[s].line);
        const Eigen::Vector3d centre(x(l), x(l + 1), x(offset));
        for (std::size_t i = 0; i < sphere_local[s].size(); ++i)
          add_point((sphere_local[s][i] - centre).eval(), radius,
                    weighted ? spheres[s].weights[i] : 1.0, sphere_block[s], sphere_coupling[s],
                    sphere_gradient[s], q, k);
      }
    }
    return squares;
  };
  auto whole_system = [&](Eigen::MatrixXd& normal, Eigen::VectorXd& gradient) {
    normal.setZero(size, size);
    gradient.resize(size);
    for (Eigen::Index l = 0; l < lines; ++l) {
      normal.block<2, 2>(2 * l, 2 * l) = line_block[static_cast<std::size_t>(l)];
      gradient.segment<2>(2 * l) = line_gradient[static_cast<std::size_t>(l)];
    }
    for (std::size_t k = 0; k < terms.size(); ++k)
      normal.block<2, 1>(2 * static_cast<Eigen::Index>(terms[k].line),
                         first_radius + static_cast<Eigen::Index>(terms[k].radius)) += coupling[k];
    for (std::size_t s = 0; s < spheres.size(); ++s) {
      const Eigen::Index o = sphere_offset[s];
      const Eigen::Index q = first_radius + static_cast<Eigen::Index>(spheres[s].radius);
      if (spheres[s].line == kNoLine) {
        normal.block<3, 3>(o, o) = sphere_block[s];
        gradient.segment<3>(o) = sphere_gradient[s];
        normal.block<3, 1>(o, q) += sphere_coupling[s];
        continue;
      }
      const Eigen::Index l = 2 * static_cast<Eigen::Index>(spheres[s].line);
      normal.block<2, 2>(l, l) += sphere_block[s].topLeftCorner<2, 2>();
      normal.block<2, 1>(l, o) = sphere_block[s].block<2, 1>(0, 2);
      normal.block<1, 2>(o, l) = sphere_block[s].block<1, 2>(2, 0);
      normal(o, o) = sphere_block[s](2, 2);
      gradient.segment<2>(l) += sphere_gradient[s].head<2>();
      gradient(o) = sphere_gradient[s](2);
      normal.block<2, 1>(l, q) += sphere_coupling[s].head<2>();
      normal(o, q) += sphere_coupling[s](2);
    }
    normal.diagonal().tail(radius_count) = radius_diagonal;
    gradient.tail(radius_count) = radius_gradient;
    for (Eigen::Index row = first_radius; row < size; ++row)
      for (Eigen::Index col = 0; col < row; ++col) normal(row, col) = normal(col, row);
  };
  Eigen::MatrixXd normal;
  Eigen::VectorXd gradient, delta(size);
  std::vector<Eigen::Matrix2d> inverse(centres.size());
  std::vector<Eigen::Matrix3d> sphere_inverse(spheres.size());
  // Per line, with the positions of its spheres along it eliminated: its gradient, and the
  // coupling of each of its terms (cylinders, then spheres) with that term's radius.
  std::vector<Eigen::Vector2d> reduced_gradient(centres.size());
  std::vector<std::vector<std::pair<Eigen::Index, Eigen::Vector2d>>> reduced_coupling(
      centres.size());
  for (int step = 0; step < 30; ++step) {
    linearise(true);
    if (lines == 1 && sphere_count == 0) {
      whole_system(normal, gradient);
      delta = normal.ldlt().solve(-gradient);
    } else {
      // The radii's Schur complement S = D − Σ Bₗᵀ Aₗ⁻¹ Bₗ, then each line's and sphere's
      // position.
      Eigen::MatrixXd schur = radius_diagonal.asDiagonal();
      Eigen::VectorXd right = -radius_gradient;
      for (std::size_t l = 0; l < centres.size(); ++l) {
        Eigen::Matrix2d block = line_block[l];
        reduced_gradient[l] = line_gradient[l];
        std::vector<std::pair<Eigen::Index, Eigen::Vector2d>>& couplings = reduced_coupling[l];
        couplings.clear();
        for (const std::size_t a : terms_on_line[l])
          couplings.emplace_back(static_cast<Eigen::Index>(terms[a].radius), coupling[a]);
        // A sphere's position t along the line couples with the line's centre (b), its radius
        // (c) and nothing else: t = (−g_t − bᵀ δ_line − c δ_radius) / a, substituted.
        for (const std::size_t s : spheres_on_line[l]) {
          const Eigen::Matrix3d& own = sphere_block[s];
          const double along = own(2, 2), radius_along = sphere_coupling[s](2),
                       gradient_along = sphere_gradient[s](2);
          const Eigen::Vector2d cross = own.block<2, 1>(0, 2);
          const Eigen::Index q = static_cast<Eigen::Index>(spheres[s].radius);
          block += own.topLeftCorner<2, 2>() - cross * cross.transpose() / along;
          reduced_gradient[l] += sphere_gradient[s].head<2>() - cross * (gradient_along / along);
          couplings.emplace_back(q, sphere_coupling[s].head<2>() - cross * (radius_along / along));
          schur(q, q) -= radius_along * radius_along / along;
          right(q) += radius_along * gradient_along / along;
        }
        inverse[l] = block.inverse();
        for (const auto& [qa, ca] : couplings) {
          const Eigen::Vector2d spread = inverse[l] * ca;
          right(qa) += spread.dot(reduced_gradient[l]);
          for (const auto& [qb, cb] : couplings) schur(qa, qb) -= spread.dot(cb);
        }
      }
      for (std::size_t s = 0; s < spheres.size(); ++s) {
        if (spheres[s].line != kNoLine) continue;
        sphere_inverse[s] = sphere_block[s].inverse();
        const Eigen::Vector3d spread = sphere_inverse[s] * sphere_coupling[s];
        const Eigen::Index q = static_cast<Eigen::Index>(spheres[s].radius);
        right(q) += spread.dot(sphere_gradient[s]);
        schur(q, q) -= spread.dot(sphere_coupling[s]);
      }
      delta.tail(radius_count) = schur.ldlt().solve(right);
      for (std::size_t l = 0; l < centres.size(); ++l) {
        Eigen::Vector2d rest = -reduced_gradient[l];
        for (const auto& [q, c] : reduced_coupling[l]) rest -= c * delta(first_radius + q);
        delta.segment<2>(2 * static_cast<Eigen::Index>(l)) = inverse[l] * rest;
      }
      for (std::size_t s = 0; s < spheres.size(); ++s) {
        const double radius_step =
            delta(first_radius + static_cast<Eigen::Index>(spheres[s].radius));
        if (spheres[s].line == kNoLine) {
          const Eigen::Vector3d rest = -sphere_gradient[s] - sphere_coupling[s] * radius_step;
          delta.segment<3>(sphere_offset[s]) = sphere_inverse[s] * rest;
        } else {
          const Eigen::Vector2d line_step =
              delta.segment<2>(2 * static_cast<Eigen::Index>(spheres[s].line));
          delta(sphere_offset[s]) =
              (-sphere_gradient[s](2) - sphere_block[s].block<2, 1>(0, 2).dot(line_step) -
               sphere_coupling[s](2) * radius_step) /
              sphere_block[s](2, 2);
        }
      }
    }
    if (!delta.allFinite()) return std::nullopt;
    x += delta;
    if (!(delta.norm() > 1e-14 * x.norm())) break;
  }
  const auto fitted_radii = x.tail(radius_count);
  if (!x.allFinite() || !(fitted_radii.minCoeff() > 0)) return std::nullopt;
  const double squares = linearise(false);
  if (count <= static_cast<std::size_t>(size)) return std::nullopt;
  JointFit fit;
  for (Eigen::Index l = 0; l < lines; ++l) fit.centres.emplace_back(x.segment<2>(2 * l));
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    if (spheres[s].line == kNoLine) {
      fit.sphere_centres.emplace_back(x.segment<3>(sphere_offset[s]));
      continue;
    }
    const Eigen::Vector3d& direction = directions[spheres[s].line];
    const auto [u, v] = orthonormal_pair(direction);
    const Eigen::Vector2d& centre = fit.centres[spheres[s].line];
    fit.sphere_centres.emplace_back(centre.x() * u + centre.y() * v +
                                    x(sphere_offset[s]) * direction);
  }
  fit.radii.assign(fitted_radii.data(), fitted_radii.data() + fitted_radii.size());
  for (std::size_t k = 0; k < terms.size() + spheres.size(); ++k)
    fit.rms.push_back(std::max(
        std::sqrt(term_squares[k] / double(std::max<std::size_t>(term_count[k], 1))),
        kResolution *
            fit.radii[k < terms.size() ? terms[k].radius : spheres[k - terms.size()].radius]));
  if (with_covariance) {
    whole_system(normal, gradient);
    const double largest_radius = fitted_radii.maxCoeff();
    fit.covariance = normal.inverse() *
                     std::max(squares / static_cast<double>(count - static_cast<std::size_t>(size)),
                              kResolution * kResolution * largest_radius * largest_radius);
    if (!fit.covariance.allFinite()) return std::nullopt;
  }
  return fit;
}

struct CoaxialFit {
  Eigen::Vector2d centre;
  std::vector<double> radii;
  std::vector<double> rms;  // per member, unweighted
  std::vector<double> radius_variances;
  Eigen::Matrix2d centre_covariance = Eigen::Matrix2d::Zero();
};

std::optional<CoaxialFit> fit_coaxial(const Eigen::Vector3d& axis, const Eigen::Vector2d& centre,
                                      std::span<const CoaxialMember> members) {
  std::vector<CylinderTerm> terms;
  std::vector<double> radii;
  for (std::size_t k = 0; k < members.size(); ++k) {
    terms.push_back({members[k].points, members[k].weights, 0, k});
    radii.push_back(members[k].radius);
  }
  std::optional<JointFit> joint =
      fit_cylinders_and_spheres({&axis, 1}, {&centre, 1}, {}, radii, terms, {}, true);
  if (!joint) return std::nullopt;
  CoaxialFit fit;
  fit.centre = joint->centres[0];
  fit.radii = std::move(joint->radii);
  fit.rms = std::move(joint->rms);
  fit.centre_covariance = joint->covariance.topLeftCorner<2, 2>();
  for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(members.size()); ++k)
    fit.radius_variances.push_back(joint->covariance(2 + k, 2 + k));
  return fit;
}

// `cylinder` refitted alone on its inliers with the axis direction `direction`, from its own axis
// point and radius.
std::optional<CoaxialFit> fit_alone(const Primitive& cylinder, const Eigen::Vector3d& direction,
                                    std::span<const Vec3> points, std::span<const double> weights) {
  const auto [u, v] = orthonormal_pair(direction);
  const Eigen::Vector2d centre(u.dot(to_eigen(cylinder.point)), v.dot(to_eigen(cylinder.point)));
  const CoaxialMember alone{points, weights, cylinder.radius};
  return fit_coaxial(direction, centre, {&alone, 1});
}

// The weighted mean of direction · x over the points of `clusters`.
double middle_along(const Eigen::Vector3d& direction, std::span<const std::size_t> clusters,
                    const std::vector<std::vector<Vec3>>& points,
                    const std::vector<std::vector<double>>& weights) {
  double total = 0, sum = 0;
  for (const std::size_t c : clusters)
    for (std::size_t i = 0; i < points[c].size(); ++i) {
      total += weights[c][i];
      sum += weights[c][i] * direction.dot(to_eigen(points[c][i]));
    }
  return total > 0 ? sum / total : 0;
}

// A cylinder of a direction group, refitted alone with the group's direction.
struct AlignedCylinder {
  std::size_t cluster = 0;
  CoaxialFit fit;
  double middle = 0;  // where its inliers are along the direction: middle_along()
};

// Cylinder `c` refitted alone with `direction` (fit_alone()), and where it is along it.
std::optional<AlignedCylinder> aligned_cylinder(std::size_t c, const Primitive& cylinder,
                                                const Eigen::Vector3d& direction,
                                                const std::vector<std::vector<Vec3>>& points,
                                                const std::vector<std::vector<double>>& weights) {
  std::optional<CoaxialFit> fit = fit_alone(cylinder, direction, points[c], weights[c]);
  if (!fit) return std::nullopt;
  return AlignedCylinder{c, std::move(*fit), middle_along(direction, {&c, 1}, points, weights)};
}

// The information-weighted mean of axis positions: where a coaxial set's axis is, and how well.
struct PooledCentre {
  Eigen::Matrix2d information = Eigen::Matrix2d::Zero();
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero();  // Σ information × centre

  void add(const CoaxialFit& fit) { add(fit.centre, fit.centre_covariance); }
  void add(const Eigen::Vector2d& centre, const Eigen::Matrix2d& covariance) {
    const Eigen::Matrix2d own = covariance.inverse();
    information += own;
    weighted += own * centre;
  }
  Eigen::Vector2d centre() const { return information.ldlt().solve(weighted); }
  Eigen::Matrix2d covariance() const { return information.inverse(); }
};

// Visited from the best-determined direction, each joins the group it is within the significance
// (or the angle tolerance) of (the best score), else starts one.
std::vector<DirectionGroup> group_directions(const std::vector<Oriented>& items,
                                             const RegularityOptions& options) {
  std::vector<std::size_t> order(items.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return items[a].variance < items[b].variance;
  });
  const double max_angle = options.max_angle_degrees * std::numbers::pi / 180;
  std::vector<DirectionGroup> groups;
  for (const std::size_t i : order) {
    const Oriented& item = items[i];
    std::size_t best = groups.size();
    double best_score = options.significance * options.significance;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const double angle = angle_between_lines(item.direction, groups[g].direction);
      if (angle > max_angle) continue;
      Eigen::Vector3d direction = groups[g].direction;
      if (direction.dot(item.direction) < 0) direction = -direction;
      const Eigen::Vector2d delta = item.frame.transpose() * direction;
      const Eigen::Matrix2d combined =
          item.covariance + item.frame.transpose() * groups[g].covariance * item.frame;
      const double score =
          tolerated(delta.dot(combined.ldlt().solve(delta)),
                    options.significance * options.significance, angle, options.angle_tolerance);
      if (score <= best_score) {
        best_score = score;
        best = g;
      }
    }
    if (best == groups.size()) groups.emplace_back().direction = item.direction;
    DirectionGroup& group = groups[best];
    group.members.push_back(i);
    group.information += direction_information(item);
    form_direction(group);
  }
  return groups;
}

// Σ w and the weighted centroid of `points` (not finite when Σ w is 0).
struct WeightedCentroid {
  Eigen::Vector3d centroid;
  double weight = 0;
};
WeightedCentroid weighted_centroid(std::span<const Vec3> points, std::span<const double> weights) {
  WeightedCentroid middle{Eigen::Vector3d::Zero()};
  for (std::size_t k = 0; k < points.size(); ++k) {
    middle.weight += weights[k];
    middle.centroid += weights[k] * to_eigen(points[k]);
  }
  middle.centroid /= middle.weight;
  return middle;
}

// The plane with normal ±`direction` (its own side) through its inliers' weighted centroid;
// false (the plane unchanged) when they weigh nothing.
bool align_plane(Primitive& plane, const Eigen::Vector3d& direction, std::span<const Vec3> points,
                 std::span<const double> weights) {
  const WeightedCentroid middle = weighted_centroid(points, weights);
  if (!(middle.weight > 0)) return false;
  plane.axis = to_vec3(direction.dot(to_eigen(plane.axis)) < 0 ? -direction : direction);
  plane.point = to_vec3(middle.centroid);
  return true;
}

// The covariance of a direction's tilt (radians², 3x3) in orthonormal_pair(direction)
// coordinates.
Eigen::Matrix2d tilt_in_frame(const Eigen::Vector3d& direction, const Eigen::Matrix3d& covariance) {
  const auto [u, v] = orthonormal_pair(direction);
  Eigen::Matrix<double, 3, 2> frame;
  frame << u, v;
  return frame.transpose() * covariance * frame;
}

// Sets of cylinders (indices into `cylinders`, sorted best-located first) whose axes are one line
// within the significance: each joins the first set whose information-weighted axis it is near,
// counting the direction's tilt (`tilt`, radians², orthonormal_pair(direction) coordinates) over
// the distance along it from the set's first member, as the coplanar sets do; or within the length
// tolerance of it. An axis known less well than the radius (a nearly flat cylinder) joins none.
std::vector<std::vector<std::size_t>> coaxial_sets(const std::vector<AlignedCylinder>& cylinders,
                                                   const Eigen::Matrix2d& tilt,
                                                   double significance2, double length_tolerance) {
  std::vector<std::vector<std::size_t>> sets;
  std::vector<PooledCentre> pooled;
  for (std::size_t k = 0; k < cylinders.size(); ++k) {
    const CoaxialFit& fit = cylinders[k].fit;
    std::size_t joined = sets.size();
    const bool located = std::sqrt(fit.centre_covariance.trace()) < fit.radii[0];
    for (std::size_t s = 0; located && s < sets.size(); ++s) {
      const Eigen::Matrix2d covariance = pooled[s].covariance();
      const Eigen::Vector2d delta = fit.centre - covariance * pooled[s].weighted;
      const double apart = cylinders[k].middle - cylinders[sets[s][0]].middle;
      const Eigen::Matrix2d combined = fit.centre_covariance + covariance + apart * apart * tilt;
      if (delta.dot(combined.ldlt().solve(delta)) <= significance2 ||
          within_tolerance(delta.norm(), length_tolerance)) {
        joined = s;
        break;
      }
    }
    if (joined == sets.size()) {
      sets.emplace_back();
      pooled.emplace_back();
    }
    sets[joined].push_back(k);
    pooled[joined].add(fit);
  }
  return sets;
}

// The significance at which each of `tests` tests must be passed for all of them to fail together
// as rarely as one test at `significance` does (Bonferroni: the two-sided normal tail divided by
// their number).
double family_significance(double significance, std::size_t tests) {
  const double tail = std::erfc(significance / std::numbers::sqrt2) / static_cast<double>(tests);
  double low = significance, high = significance + 40;
  for (int step = 0; step < 100; ++step) {
    const double middle = (low + high) / 2;
    (std::erfc(middle / std::numbers::sqrt2) > tail ? low : high) = middle;
  }
  return high;
}

// Whether a 2D position of covariance `covariance` is known to within `bound` at the
// significance, in its worst direction (the interval rule of the spheres' centres).
bool known_within(const Eigen::Matrix2d& covariance, double significance, double bound) {
  const double half_difference = (covariance(0, 0) - covariance(1, 1)) / 2;
  const double largest =
      (covariance(0, 0) + covariance(1, 1)) / 2 + std::hypot(half_difference, covariance(0, 1));
  return significance * std::sqrt(largest) <= bound;
}

// The surfaces with a radius, for the spheres on axes and the equal radii: the cylinders refitted
// so far, each on an axis line (coaxial ones on a shared one), and the spheres, each on its
// centre (on a line, once centred on one).
struct SettledSurfaces {
  struct Line {
    Eigen::Vector3d direction;
    Eigen::Vector2d centre;  // orthonormal_pair(direction) coordinates
    // Of `centre`, the direction fixed: how well the line is placed where its points are.
    Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
    std::size_t coaxial = kNoRelation;  // its coaxial relation's index
    // Where its cylinders' points are along it (their weighted mean of direction · x), and the
    // covariance of the direction's tilt (radians², orthonormal_pair(direction) coordinates):
    // at a distance h from there the line is placed to within covariance + h² tilt.
    double middle = 0;
    Eigen::Matrix2d tilt = Eigen::Matrix2d::Zero();
  };
  struct Surface {
    std::size_t cluster = 0;
    bool sphere = false;
    std::size_t line = 0;    // into `lines`: a cylinder's; a sphere's centre's, or kNoLine
    std::size_t centre = 0;  // a sphere's, into `centres`
    double radius = 0, radius_variance = 0, rms = 0;
  };
  std::vector<Line> lines;
  std::vector<Eigen::Vector3d> centres;
  std::vector<Eigen::Matrix3d> centre_covariances;  // of each sphere's own fit
  std::vector<Surface> surfaces;
};

// The coaxial sets of a direction group's cylinders (each refitted alone with `direction`, of
// tilt covariance `direction_covariance`; sorted here, best-located first), each with its joint
// fit (none for a lone cylinder): coaxial_sets(), then the joint fit `fit_set(set)` (an optional
// fit whose `rms` are its members', in the set's order) must explain each member as its own fit
// did, within the significance corrected for the number of members: a member whose residual sum
// rises by more than its square times its residual variance (it has 2 degrees of freedom fewer)
// leaves the set, the worst first, and starts one of its own.
template <class FitSet>
auto fit_coaxial_sets(const Eigen::Vector3d& direction, const Eigen::Matrix3d& direction_covariance,
                      std::vector<AlignedCylinder>& cylinders, const RegularityOptions& options,
                      const std::vector<std::vector<Vec3>>& points, const FitSet& fit_set) {
  const double significance = options.significance;
  using Fit = std::invoke_result_t<FitSet, const std::vector<std::size_t>&>;  // optional
  std::stable_sort(cylinders.begin(), cylinders.end(),
                   [](const AlignedCylinder& a, const AlignedCylinder& b) {
                     return a.fit.centre_covariance.trace() < b.fit.centre_covariance.trace();
                   });
  std::vector<std::vector<std::size_t>> sets =
      coaxial_sets(cylinders, tilt_in_frame(direction, direction_covariance),
                   significance * significance, options.length_tolerance);
  std::vector<std::pair<std::vector<std::size_t>, Fit>> fitted;
  for (std::size_t s = 0; s < sets.size(); ++s) {
    Fit joint;
    while (sets[s].size() > 1) {
      Fit fit = fit_set(sets[s]);
      const double bound = family_significance(significance, sets[s].size());
      std::size_t worst = sets[s].size();
      double worst_excess = 1;
      for (std::size_t j = 0; j < sets[s].size(); ++j) {
        const AlignedCylinder& member = cylinders[sets[s][j]];
        const double excess =
            fit ? residual_excess(member.fit.rms[0], fit->rms[j], points[member.cluster].size(),
                                  bound * bound, 3, options.length_tolerance)
                : std::numeric_limits<double>::infinity();
        if (excess > worst_excess) {
          worst_excess = excess;
          worst = j;
        }
      }
      if (worst == sets[s].size()) {
        joint = std::move(fit);
        break;
      }
      sets.push_back({sets[s][worst]});
      sets[s].erase(sets[s].begin() + static_cast<std::ptrdiff_t>(worst));
    }
    fitted.emplace_back(sets[s], std::move(joint));
  }
  return fitted;
}

// The joint fit with `direction` of the cylinders `set` (indices into `cylinders`): one line
// through them, each keeping its own radius, from the information-weighted mean of their own
// lines.
std::optional<CoaxialFit> fit_on_one_line(const Eigen::Vector3d& direction,
                                          const std::vector<AlignedCylinder>& cylinders,
                                          const std::vector<std::size_t>& set,
                                          const std::vector<std::vector<Vec3>>& points,
                                          const std::vector<std::vector<double>>& weights) {
  std::vector<CoaxialMember> members;
  PooledCentre pooled;
  for (const std::size_t k : set) {
    const std::size_t c = cylinders[k].cluster;
    members.push_back({points[c], weights[c], cylinders[k].fit.radii[0]});
    pooled.add(cylinders[k].fit);
  }
  return fit_coaxial(direction, pooled.centre(), members);
}

// A coaxial set fitted on one line of free direction: the set as one item of its direction group,
// and the members' residuals.
struct FreeLineFit {
  Oriented item;
  std::vector<double> rms;  // per member, unweighted, at least kResolution × its radius
};

// A coaxial set's members fitted with one axis line whose direction is free too (Gauss–Newton
// from `direction` and the set's joint fit with it, weighted steps as the joint fits take them),
// as one item of its direction group: its direction, and how well all its points determine it
// together (from the unweighted residuals, as oriented_cylinder()'s). Sharing the line ties the
// members: two short steps of a shaft far apart fix the axis better than each does alone. Nothing
// when the iteration does not settle or a radius ends non-positive.
std::optional<FreeLineFit> fit_free_line(Eigen::Vector3d direction, const CoaxialFit& start,
                                         std::span<const std::size_t> clusters,
                                         const std::vector<std::vector<Vec3>>& points,
                                         const std::vector<std::vector<double>>& weights) {
  const Eigen::Index members = static_cast<Eigen::Index>(clusters.size());
  const Eigen::Index parameters = 4 + members;
  std::vector<double> radii = start.radii;
  const double scale = *std::max_element(radii.begin(), radii.end());
  std::size_t count = 0;
  for (const std::size_t c : clusters) count += points[c].size();
  if (!(scale > 0) || count <= static_cast<std::size_t>(parameters)) return std::nullopt;
  Eigen::Vector3d u, v;  // not a structured binding: the lambdas below capture them
  std::tie(u, v) = orthonormal_pair(direction);
  Eigen::Vector3d pivot = start.centre.x() * u + start.centre.y() * v;
  // The tilt pivots where the points are along the line, so that it hardly moves them on average.
  pivot += direction * (middle_along(direction, clusters, points, weights) - direction.dot(pivot));
  // Parameters: the tilt along u and v times `scale` (one unit in every column), the line's shift
  // along u and v, the radii. Residuals e = |Q(x − pivot)| − r, Q = I − d dᵀ; `visit(k, i, e,
  // line)` gets point i of member k, its residual and its derivatives: `line` for the line's four
  // parameters, −1 for its radius.
  const auto for_each_residual = [&](const auto& visit) {
    for (Eigen::Index k = 0; k < members; ++k) {
      const std::size_t c = clusters[static_cast<std::size_t>(k)];
      for (std::size_t i = 0; i < points[c].size(); ++i) {
        const Eigen::Vector3d d = to_eigen(points[c][i]) - pivot;
        const double t = direction.dot(d);
        const Eigen::Vector3d radial = d - t * direction;
        const double length = radial.norm();
        if (!(length > 0)) continue;
        const Eigen::Vector3d normal = radial / length;
        visit(k, weights[c][i], length - radii[static_cast<std::size_t>(k)],
              Eigen::Vector4d(-t / scale * normal.dot(u), -t / scale * normal.dot(v),
                              -normal.dot(u), -normal.dot(v)));
      }
    }
  };
  // Adds a residual's Jacobian row, times `weight`, to the (symmetric) normal matrix `matrix`:
  // its upper part only, the lower filled by symmetric().
  const auto add_row = [](Eigen::MatrixXd& matrix, Eigen::Index k, double weight,
                          const Eigen::Vector4d& line) {
    matrix.topLeftCorner<4, 4>() += weight * line * line.transpose();
    matrix.block<4, 1>(0, 4 + k) -= weight * line;
    matrix(4 + k, 4 + k) += weight;
  };
  const auto symmetric = [members](Eigen::MatrixXd& matrix) {
    matrix.bottomLeftCorner(members, 4) = matrix.topRightCorner(4, members).transpose();
  };
  Eigen::MatrixXd weighted(parameters, parameters);
  Eigen::VectorXd gradient(parameters);
  constexpr int kMaxSteps = 30;
  for (int step = 0;; ++step) {
    weighted.setZero();
    gradient.setZero();
    for_each_residual([&](Eigen::Index k, double w, double e, const Eigen::Vector4d& line) {
      add_row(weighted, k, w, line);
      gradient.head<4>() += w * e * line;
      gradient(4 + k) -= w * e;
    });
    symmetric(weighted);
    const Eigen::VectorXd delta = -weighted.ldlt().solve(gradient);
    if (!delta.allFinite()) return std::nullopt;
    if (delta.cwiseAbs().maxCoeff() <= 1e-12 * scale) break;
    if (step == kMaxSteps) return std::nullopt;
    direction = (direction + delta(0) / scale * u + delta(1) / scale * v).normalized();
    pivot += delta(2) * u + delta(3) * v;
    for (Eigen::Index k = 0; k < members; ++k) {
      radii[static_cast<std::size_t>(k)] += delta(4 + k);
      if (!(radii[static_cast<std::size_t>(k)] > 0)) return std::nullopt;
    }
    std::tie(u, v) = orthonormal_pair(direction);
    pivot +=
        direction * (middle_along(direction, clusters, points, weights) - direction.dot(pivot));
  }
  // At the solution: the unweighted information and each member's residual sum.
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(parameters, parameters);
  std::vector<double> member_squares(clusters.size(), 0);
  double squares = 0;
  for_each_residual([&](Eigen::Index k, double, double e, const Eigen::Vector4d& line) {
    add_row(information, k, 1, line);
    member_squares[static_cast<std::size_t>(k)] += e * e;
  });
  symmetric(information);
  for (const double own : member_squares) squares += own;
  const double residual_variance =
      std::max(squares / double(count - static_cast<std::size_t>(parameters)),
               kResolution * kResolution * scale * scale);
  const Eigen::MatrixXd covariance = information.inverse() * residual_variance;
  if (!covariance.allFinite()) return std::nullopt;
  FreeLineFit fit;
  Oriented& item = fit.item;
  item.cluster = clusters[0];
  item.direction = direction;
  item.frame.col(0) = u;
  item.frame.col(1) = v;
  item.covariance = covariance.topLeftCorner<2, 2>() / (scale * scale);
  item.variance = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(item.covariance).eigenvalues()(1);
  if (!std::isfinite(item.variance) || !(item.variance > 0)) return std::nullopt;
  for (std::size_t k = 0; k < clusters.size(); ++k)
    fit.rms.push_back(std::max(std::sqrt(member_squares[k] / double(points[clusters[k]].size())),
                               kResolution * radii[k]));
  return fit;
}

// Refits the cylinders of a direction group: each coaxial set around one axis line (each member
// keeping its own radius), the others alone with the group's direction. Appends the coaxial sets
// of two or more to `relations`, and every cylinder refitted to `settled`.
void align_cylinders(const Eigen::Vector3d& direction, const Eigen::Matrix3d& direction_covariance,
                     std::vector<AlignedCylinder> cylinders, const RegularityOptions& options,
                     std::vector<Primitive>& primitives,
                     const std::vector<std::vector<Vec3>>& points,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations, SettledSurfaces& settled) {
  const auto sets =
      fit_coaxial_sets(direction, direction_covariance, cylinders, options, points,
                       [&](const std::vector<std::size_t>& set) {
                         return fit_on_one_line(direction, cylinders, set, points, weights);
                       });
  for (const auto& [members, fit] : sets) {
    const CoaxialFit& joint = fit ? *fit : cylinders[members[0]].fit;
    std::size_t coaxial_index = kNoRelation;
    if (members.size() > 1) {
      coaxial_index = relations.size();
      Relation& coaxial = relations.emplace_back();
      coaxial.kind = Relation::Kind::Coaxial;
      for (const std::size_t k : members) coaxial.members.push_back(cylinders[k].cluster);
      std::sort(coaxial.members.begin(), coaxial.members.end());
    }
    const std::size_t line = settled.lines.size();
    std::vector<std::size_t> clusters;
    for (const std::size_t k : members) clusters.push_back(cylinders[k].cluster);
    settled.lines.push_back({direction, joint.centre, joint.centre_covariance, coaxial_index,
                             middle_along(direction, clusters, points, weights),
                             tilt_in_frame(direction, direction_covariance)});
    for (std::size_t j = 0; j < members.size(); ++j) {
      const std::size_t c = clusters[j];
      place_cylinder(primitives[c], direction, joint.centre, joint.radii[j]);
      settled.surfaces.push_back(
          {c, false, line, 0, joint.radii[j], joint.radius_variances[j], joint.rms[j]});
    }
  }
}

// A plane aligned with a group's direction, by where it is along it.
struct AlignedPlane {
  std::size_t cluster = 0;
  Eigen::Vector3d centroid;  // its inliers' weighted centroid: the aligned plane's point
  double offset = 0;         // direction · centroid
  double variance = 0;       // the offset's
  double weight = 0;         // Σ w
};

// Its offset along `direction` (that of its inliers' weighted centroid, where align_plane()
// puts it), and how well it is known: the weighted mean of the inliers' offsets has variance
// σ̂² Σw² / (Σw)², σ̂² their weighted mean square about it with the plane's 3 degrees of freedom
// taken (floored at the resolution of its extent, as its direction's is).
std::optional<AlignedPlane> aligned_plane(std::size_t cluster, const Eigen::Vector3d& direction,
                                          std::span<const Vec3> points,
                                          std::span<const double> weights) {
  const std::size_t n = points.size();
  if (n < 6) return std::nullopt;
  const WeightedCentroid middle = weighted_centroid(points, weights);
  if (!(middle.weight > 0)) return std::nullopt;
  AlignedPlane plane{cluster, middle.centroid};
  plane.weight = middle.weight;
  plane.offset = direction.dot(plane.centroid);
  double weight2 = 0, squares = 0, extent2 = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d e = to_eigen(points[k]) - plane.centroid;
    const double r = direction.dot(e);
    weight2 += weights[k] * weights[k];
    squares += weights[k] * r * r;
    extent2 += weights[k] * (e.squaredNorm() - r * r);
  }
  const double residual_variance = std::max(squares / plane.weight * double(n) / double(n - 3),
                                            kResolution * kResolution * extent2 / plane.weight);
  plane.variance = residual_variance * weight2 / (plane.weight * plane.weight);
  return plane;
}

// The planes of `set` (aligned with `direction` through their inliers' weighted centroids) made
// one plane through all their inliers, each keeping its side: the least-squares offset with the
// direction fixed is the weighted mean of theirs. Appends the Coplanar relation.
void share_one_plane(const Eigen::Vector3d& direction, const std::vector<std::size_t>& set,
                     std::vector<Primitive>& primitives,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations) {
  double weight = 0, weighted = 0;
  for (const std::size_t c : set) {
    double own = 0;
    for (const double w : weights[c]) own += w;
    weight += own;
    weighted += own * direction.dot(to_eigen(primitives[c].point));
  }
  const double shared = weighted / weight;
  for (const std::size_t c : set) {
    const Eigen::Vector3d point = to_eigen(primitives[c].point);
    primitives[c].point = to_vec3(point - (direction.dot(point) - shared) * direction);
  }
  relations.push_back({Relation::Kind::Coplanar, set, {}});
}

// Sets of a direction group's planes (aligned with its direction, of covariance
// `direction_covariance`) that are one plane within the significance: the fragments
// of one face that a hole, a boss or the hierarchy cut apart. Best-located first, each joins the
// first set whose pooled offset it is within the significance of, counting both offsets'
// variances and the direction's tilt over the distance between its centroid and the set's first
// member's; else it starts one. A set must then be explained by one plane of the direction
// through all its inliers as each member was by its own: the guard of the coaxial sets (the
// significance corrected for the number of members), the worst member leaving first. Returns the
// sets of two or more, as clusters, increasing.
std::vector<std::vector<std::size_t>> coplanar_sets(const Eigen::Matrix3d& direction_covariance,
                                                    std::vector<AlignedPlane> planes,
                                                    const RegularityOptions& options) {
  const double significance = options.significance;
  std::stable_sort(planes.begin(), planes.end(), [](const AlignedPlane& a, const AlignedPlane& b) {
    return a.variance < b.variance;
  });
  struct Set {
    std::vector<std::size_t> planes;       // indices into `planes`
    double information = 0, weighted = 0;  // Σ 1/variance, Σ offset/variance
  };
  const double bound = chi_square_bound(significance, 1);
  std::vector<Set> sets;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    std::size_t joined = sets.size();
    for (std::size_t s = 0; s < sets.size() && joined == sets.size(); ++s) {
      const double offset = planes[i].offset - sets[s].weighted / sets[s].information;
      const Eigen::Vector3d apart = planes[i].centroid - planes[sets[s].planes[0]].centroid;
      const double variance =
          planes[i].variance + 1 / sets[s].information + apart.dot(direction_covariance * apart);
      if (offset * offset <= bound * variance ||
          within_tolerance(std::abs(offset), options.length_tolerance))
        joined = s;
    }
    if (joined == sets.size()) sets.emplace_back();
    sets[joined].planes.push_back(i);
    sets[joined].information += 1 / planes[i].variance;
    sets[joined].weighted += planes[i].offset / planes[i].variance;
  }
  std::vector<std::vector<std::size_t>> coplanar;
  for (std::size_t s = 0; s < sets.size(); ++s) {
    // Moved out: a member that leaves starts a set of its own, which may reallocate `sets`.
    std::vector<std::size_t> set = std::move(sets[s].planes);
    while (set.size() > 1) {
      // One plane through all the members' inliers: the weighted mean of their offsets.
      double weight = 0, weighted = 0;
      Eigen::Vector3d middle = Eigen::Vector3d::Zero();  // where the shared plane pivots
      for (const std::size_t i : set) {
        weight += planes[i].weight;
        weighted += planes[i].weight * planes[i].offset;
        middle += planes[i].weight * planes[i].centroid;
      }
      const double shared = weighted / weight;
      middle /= weight;
      const double member_bound = family_significance(significance, set.size());
      std::size_t worst = set.size();
      double worst_excess = 1;
      for (std::size_t j = 0; j < set.size(); ++j) {
        // The member's residual sum rises by its weight times the move², against the bound
        // times its residual variance: the move against its offset's standard deviation, with
        // the direction's tilt over its distance from where the shared plane pivots.
        const AlignedPlane& plane = planes[set[j]];
        const double moved = plane.offset - shared;
        const Eigen::Vector3d apart = plane.centroid - middle;
        const double excess =
            tolerated(moved * moved /
                          (member_bound * member_bound *
                           (plane.variance + apart.dot(direction_covariance * apart))),
                      1, std::abs(moved), options.length_tolerance);
        if (excess > worst_excess) {
          worst_excess = excess;
          worst = j;
        }
      }
      if (worst == set.size()) break;
      sets.push_back({{set[worst]}});
      set.erase(set.begin() + static_cast<std::ptrdiff_t>(worst));
    }
    if (set.size() < 2) continue;
    std::vector<std::size_t>& clusters = coplanar.emplace_back();
    for (const std::size_t i : set) clusters.push_back(planes[i].cluster);
    std::sort(clusters.begin(), clusters.end());
  }
  return coplanar;
}

// `joined` counts as the members of `set` (clusters, increasing) in their group's direction: the
// sum of the members' information gives way to its. The group's direction is formed again by the
// caller.
void count_as_one(DirectionGroup& group, const std::vector<Oriented>& items,
                  std::span<const std::size_t> set, const Oriented& joined) {
  for (const std::size_t i : group.members)
    if (std::binary_search(set.begin(), set.end(), items[i].cluster))
      group.information -= direction_information(items[i]);
  group.information += direction_information(joined);
}

// Each coplanar set of a group counts as one plane: the union's scatter (about the union's
// centroid) also holds how far apart the fragments lie, so the direction is known better than
// from the members' own scatters. Returns whether any did.
bool count_coplanar_as_one(DirectionGroup& group, const std::vector<Oriented>& items,
                           const std::vector<std::vector<std::size_t>>& sets,
                           const std::vector<std::vector<Vec3>>& points) {
  bool counted = false;
  for (const std::vector<std::size_t>& set : sets) {
    std::vector<Vec3> union_points;
    for (const std::size_t c : set)
      union_points.insert(union_points.end(), points[c].begin(), points[c].end());
    const std::optional<Oriented> joined = oriented_plane(set[0], union_points);
    if (!joined || !(joined->variance > 0)) continue;
    count_as_one(group, items, set, *joined);
    counted = true;
  }
  return counted;
}

// Each coaxial set of a group's cylinders counts as one item: its members fitted on one line of
// free direction. The sets are align_cylinders()'s, except that the joint fit a set must pass is
// this one: the group's direction, still to be settled, need not suit all members at once (two
// steps of a shaft far apart tell the axis better together than the group's direction gives it).
// Returns whether any set counted.
bool count_coaxial_as_one(DirectionGroup& group, const std::vector<Oriented>& items,
                          const std::vector<Primitive>& primitives,
                          const std::vector<std::vector<Vec3>>& points,
                          const std::vector<std::vector<double>>& weights,
                          const RegularityOptions& options) {
  const auto is_cylinder = [&](std::size_t i) {
    return primitives[items[i].cluster].type == PrimitiveType::Cylinder;
  };
  if (std::count_if(group.members.begin(), group.members.end(), is_cylinder) < 2) return false;
  std::vector<AlignedCylinder> cylinders;
  for (const std::size_t i : group.members) {
    const std::size_t c = items[i].cluster;
    if (primitives[c].type != PrimitiveType::Cylinder) continue;
    if (std::optional<AlignedCylinder> cylinder =
            aligned_cylinder(c, primitives[c], group.direction, points, weights))
      cylinders.push_back(std::move(*cylinder));
  }
  if (cylinders.size() < 2) return false;
  // The clusters of `set`, in its order.
  const auto clusters_of = [&](const std::vector<std::size_t>& set) {
    std::vector<std::size_t> clusters(set.size());
    for (std::size_t j = 0; j < set.size(); ++j) clusters[j] = cylinders[set[j]].cluster;
    return clusters;
  };
  const auto sets = fit_coaxial_sets(
      group.direction, group.covariance, cylinders, options, points,
      [&](const std::vector<std::size_t>& set) -> std::optional<FreeLineFit> {
        const std::optional<CoaxialFit> start =
            fit_on_one_line(group.direction, cylinders, set, points, weights);
        if (!start) return std::nullopt;
        return fit_free_line(group.direction, *start, clusters_of(set), points, weights);
      });
  bool counted = false;
  for (const auto& [set, fit] : sets) {
    if (!fit) continue;
    std::vector<std::size_t> clusters = clusters_of(set);
    std::sort(clusters.begin(), clusters.end());
    count_as_one(group, items, clusters, fit->item);
    counted = true;
  }
  return counted;
}

// Refits line l with its cylinders and the spheres `spheres` (indices into settled.surfaces) on
// it, each sphere one parameter along it: while any member's residual sum rises by more than the
// significance, corrected for the number of members, allows, the sphere whose rise is largest
// leaves. Writes the line, its members and their primitives back, and adds the spheres to the
// line's coaxial relation (started when it has none), unless fewer spheres than `fewest` stay.
// Returns whether it did.
bool settle_on_line(SettledSurfaces& settled, std::size_t l,
                    const std::vector<std::size_t>& cylinders, std::vector<std::size_t> spheres,
                    const RegularityOptions& options, std::vector<Primitive>& primitives,
                    const std::vector<std::vector<Vec3>>& points,
                    const std::vector<std::vector<double>>& weights,
                    std::vector<Relation>& relations, std::size_t fewest = 1) {
  std::vector<SettledSurfaces::Surface>& surfaces = settled.surfaces;
  SettledSurfaces::Line& line = settled.lines[l];
  std::optional<JointFit> fit;
  std::vector<CylinderTerm> terms;
  std::vector<SphereTerm> sphere_terms;
  while (spheres.size() >= fewest) {
    terms.clear();
    sphere_terms.clear();
    std::vector<double> radii;
    std::vector<Eigen::Vector3d> centres;
    for (const std::size_t k : cylinders) {
      const std::size_t c = surfaces[k].cluster;
      terms.push_back({points[c], weights[c], 0, radii.size()});
      radii.push_back(surfaces[k].radius);
    }
    for (const std::size_t k : spheres) {
      const std::size_t c = surfaces[k].cluster;
      sphere_terms.push_back({points[c], weights[c], radii.size(), 0});
      radii.push_back(surfaces[k].radius);
      centres.push_back(settled.centres[surfaces[k].centre]);
    }
    fit = fit_cylinders_and_spheres({&line.direction, 1}, {&line.centre, 1}, centres, radii, terms,
                                    sphere_terms, true);
    const std::size_t members = cylinders.size() + spheres.size();
    const double bound = family_significance(options.significance, members);
    double worst_excess = 1, worst_sphere_excess = -std::numeric_limits<double>::infinity();
    std::size_t worst_sphere = 0;
    for (std::size_t j = 0; j < members; ++j) {
      const bool is_sphere = j >= cylinders.size();
      const SettledSurfaces::Surface& surface =
          surfaces[is_sphere ? spheres[j - cylinders.size()] : cylinders[j]];
      // A sphere's own fit has 4 parameters, a cylinder's (on its direction) 3.
      const double excess =
          fit ? residual_excess(surface.rms, fit->rms[j], points[surface.cluster].size(),
                                bound * bound, is_sphere ? 4 : 3, options.length_tolerance)
              : std::numeric_limits<double>::infinity();
      worst_excess = std::max(worst_excess, excess);
      if (is_sphere && excess > worst_sphere_excess) {
        worst_sphere_excess = excess;
        worst_sphere = j - cylinders.size();
      }
    }
    if (!(worst_excess > 1)) break;
    spheres.erase(spheres.begin() + static_cast<std::ptrdiff_t>(worst_sphere));
    fit.reset();
  }
  if (!fit) return false;
  // Written back: the line, its cylinders and its spheres, with their radii's variances.
  const Eigen::Index first_radius = 2 + static_cast<Eigen::Index>(spheres.size());
  line.centre = fit->centres[0];
  line.covariance = fit->covariance.topLeftCorner<2, 2>();
  std::vector<std::size_t> members;
  for (std::size_t j = 0; j < cylinders.size() + spheres.size(); ++j) {
    const bool is_sphere = j >= cylinders.size();
    SettledSurfaces::Surface& surface =
        surfaces[is_sphere ? spheres[j - cylinders.size()] : cylinders[j]];
    const Eigen::Index q = static_cast<Eigen::Index>(j);
    surface.radius = fit->radii[j];
    surface.radius_variance = fit->covariance(first_radius + q, first_radius + q);
    surface.rms = fit->rms[j];
    Primitive& primitive = primitives[surface.cluster];
    if (is_sphere) {
      surface.line = l;
      settled.centres[surface.centre] = fit->sphere_centres[j - cylinders.size()];
      primitive.point = to_vec3(settled.centres[surface.centre]);
      primitive.radius = surface.radius;
    } else {
      place_cylinder(primitive, line.direction, line.centre, surface.radius);
    }
    members.push_back(surface.cluster);
  }
  if (line.coaxial == kNoRelation) {
    line.coaxial = relations.size();
    relations.push_back({Relation::Kind::Coaxial, {}, {}});
  }
  std::vector<std::size_t>& coaxial = relations[line.coaxial].members;
  coaxial.insert(coaxial.end(), members.begin(), members.end());
  std::sort(coaxial.begin(), coaxial.end());
  coaxial.erase(std::unique(coaxial.begin(), coaxial.end()), coaxial.end());
  return true;
}

// Spheres centred on an axis line: a ball end, a hemispherical cap, a spherical seat of a hole.
// Each sphere whose centre is within the significance of a line (Mahalanobis, over the offset in
// the line's plane, with the covariances of the centre, of the line's position and of its tilt
// times the centre's distance along it from the line's points, against the χ² bound of two
// degrees of freedom) and within
// max_radius_difference of its radius joins the nearest such line. As for the radii, an offset
// whose significance interval is wider than that joins none: the centres of sphere patches of a
// freeform surface are known to a few percent of their radii, and any line would do (bunny00's
// level of 391 clusters had 22 such pairs without this rule, none with it; CAD parts' centres are
// known to 1e-6 of their radii, fandisk's to 5e-4). Nor does a line known less well than its
// cylinders' radius (a nearly flat cylinder's axis could be anywhere). Each line's cylinders and
// spheres are then refitted together, every sphere with one parameter along the line instead of
// three; as for a coaxial set, while a member's residual sum rises by more than the significance
// corrected for the number of members allows, the sphere that rises most leaves. Appends each
// joined sphere to its line's coaxial relation, which it starts when the line had one cylinder.
void centre_spheres_on_axes(SettledSurfaces& settled, const RegularityOptions& options,
                            std::vector<Primitive>& primitives,
                            const std::vector<std::vector<Vec3>>& points,
                            const std::vector<std::vector<double>>& weights,
                            std::vector<Relation>& relations) {
  std::vector<SettledSurfaces::Surface>& surfaces = settled.surfaces;
  const std::size_t line_count = settled.lines.size();
  std::vector<std::vector<std::size_t>> cylinders_on(line_count), spheres_on(line_count);
  std::vector<double> smallest_radius(line_count, std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < surfaces.size(); ++k)
    if (!surfaces[k].sphere) {
      cylinders_on[surfaces[k].line].push_back(k);
      smallest_radius[surfaces[k].line] =
          std::min(smallest_radius[surfaces[k].line], surfaces[k].radius);
    }
  // An offset is two normals: the bound they exceed as rarely as one normal the significance.
  const double significance = options.significance;
  const double offset_bound = chi_square_bound(significance, 2);
  // Each line's frame (orthonormal_pair(direction) as rows), or none when it is not placed well
  // enough to hold a sphere.
  std::vector<std::optional<Eigen::Matrix<double, 2, 3>>> frames(line_count);
  for (std::size_t l = 0; l < line_count; ++l) {
    const SettledSurfaces::Line& line = settled.lines[l];
    if (!(std::sqrt(line.covariance.trace()) < smallest_radius[l])) continue;
    const auto [u, v] = orthonormal_pair(line.direction);
    frames[l].emplace();
    *frames[l] << u.transpose(), v.transpose();
  }
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    const SettledSurfaces::Surface& sphere = surfaces[k];
    if (!sphere.sphere) continue;
    const Eigen::Vector3d& centre = settled.centres[sphere.centre];
    const Eigen::Matrix3d& covariance = settled.centre_covariances[sphere.centre];
    const double largest_offset = options.max_radius_difference * sphere.radius;
    std::size_t nearest = line_count;
    double nearest_score = offset_bound;
    for (std::size_t l = 0; l < line_count; ++l) {
      if (!frames[l]) continue;
      const SettledSurfaces::Line& line = settled.lines[l];
      const Eigen::Matrix<double, 2, 3>& frame = *frames[l];
      const Eigen::Vector2d offset = frame * centre - line.centre;
      if (!(offset.norm() <= largest_offset)) continue;
      const double height = line.direction.dot(centre) - line.middle;
      const Eigen::Matrix2d combined =
          frame * covariance * frame.transpose() + line.covariance + height * height * line.tilt;
      if (!known_within(combined, significance, largest_offset)) continue;
      const double score = tolerated(offset.dot(combined.ldlt().solve(offset)), offset_bound,
                                     offset.norm(), options.length_tolerance);
      if (score <= nearest_score) {
        nearest_score = score;
        nearest = l;
      }
    }
    if (nearest < line_count) spheres_on[nearest].push_back(k);
  }
  for (std::size_t l = 0; l < line_count; ++l)
    if (!spheres_on[l].empty())
      settle_on_line(settled, l, cylinders_on[l], spheres_on[l], options, primitives, points,
                     weights, relations);
}

// The fewest spheres that make a line with no cylinder. Two centres fall on a line of one of the
// design directions by chance on freeform parts (bunny00's default level with `--refine 2`: 30
// pairs among its 39 directions, mech-holes-shark's 10; and 1 and 0 sets of three or more).
constexpr std::size_t kFewestSpheresOnALine = 3;

// Spheres centred on one line of a design direction with no cylinder on it: the arcs of a
// revolved profile (couplingdown has seven spheres centred on one line along z). For each
// direction a relation made exact (refitted[g] not empty), in order, the spheres on no line yet,
// best located first, each join the first set whose pooled position in the plane orthogonal to
// the direction they are within the significance of (the χ² bound of two degrees of freedom, with
// the covariances of the centre, of the pooled position and of the direction's tilt times the
// height between them) and within max_radius_difference of their radius; a centre known less well
// than that joins none. A set of kFewestSpheresOnALine or more becomes a line of its own, refitted
// with its spheres (settle_on_line, as many staying), and a coaxial relation of them.
void line_up_spheres(SettledSurfaces& settled, const std::vector<DirectionGroup>& groups,
                     const std::vector<std::vector<std::size_t>>& refitted,
                     const RegularityOptions& options, std::vector<Primitive>& primitives,
                     const std::vector<std::vector<Vec3>>& points,
                     const std::vector<std::vector<double>>& weights,
                     std::vector<Relation>& relations) {
  const double bound = chi_square_bound(options.significance, 2);
  struct Placed {
    std::size_t surface = 0;
    Eigen::Vector2d position;
    Eigen::Matrix2d covariance;
    double height = 0;
  };
  struct Set {
    std::vector<std::size_t> surfaces;
    double height = 0;  // its first member's
    PooledCentre pooled;
  };
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (refitted[g].empty()) continue;
    const Eigen::Vector3d& direction = groups[g].direction;
    const auto [u, v] = orthonormal_pair(direction);
    Eigen::Matrix<double, 2, 3> frame;
    frame << u.transpose(), v.transpose();
    const Eigen::Matrix2d tilt = tilt_in_frame(direction, groups[g].covariance);
    std::vector<Placed> placed;
    for (std::size_t k = 0; k < settled.surfaces.size(); ++k) {
      const SettledSurfaces::Surface& sphere = settled.surfaces[k];
      if (!sphere.sphere || sphere.line != kNoLine) continue;
      const Eigen::Vector3d& centre = settled.centres[sphere.centre];
      const Eigen::Matrix2d covariance =
          frame * settled.centre_covariances[sphere.centre] * frame.transpose();
      if (!known_within(covariance, options.significance,
                        options.max_radius_difference * sphere.radius))
        continue;
      placed.push_back({k, frame * centre, covariance, direction.dot(centre)});
    }
    std::stable_sort(placed.begin(), placed.end(), [](const Placed& a, const Placed& b) {
      return a.covariance.trace() < b.covariance.trace();
    });
    std::vector<Set> sets;
    for (const Placed& sphere : placed) {
      const double largest_offset =
          options.max_radius_difference * settled.surfaces[sphere.surface].radius;
      std::size_t joined = sets.size();
      for (std::size_t s = 0; s < sets.size() && joined == sets.size(); ++s) {
        const Eigen::Vector2d offset = sphere.position - sets[s].pooled.centre();
        if (!(offset.norm() <= largest_offset)) continue;  // most pairs, before any covariance
        const double height = sphere.height - sets[s].height;
        const Eigen::Matrix2d combined =
            sphere.covariance + sets[s].pooled.covariance() + height * height * tilt;
        if (offset.dot(combined.ldlt().solve(offset)) <= bound ||
            within_tolerance(offset.norm(), options.length_tolerance))
          joined = s;
      }
      if (joined == sets.size()) sets.emplace_back().height = sphere.height;
      sets[joined].surfaces.push_back(sphere.surface);
      sets[joined].pooled.add(sphere.position, sphere.covariance);
    }
    for (Set& set : sets) {
      if (set.surfaces.size() < kFewestSpheresOnALine) continue;
      std::vector<std::size_t> clusters;
      for (const std::size_t k : set.surfaces) clusters.push_back(settled.surfaces[k].cluster);
      settled.lines.push_back({direction, set.pooled.centre(), set.pooled.covariance(), kNoRelation,
                               middle_along(direction, clusters, points, weights), tilt});
      if (!settle_on_line(settled, settled.lines.size() - 1, {}, set.surfaces, options, primitives,
                          points, weights, relations, kFewestSpheresOnALine))
        settled.lines.pop_back();
    }
  }
}

// Classes of radii that are one radius within the significance: in increasing order of radius,
// a class grows while its radii stay consistent with their information-weighted mean (their χ²
// about it within chi_square_bound of its degrees of freedom) and its smallest within
// max_radius_difference of its largest (relative to the largest). A radius whose significance
// interval is wider than that bound joins none: any two such radii within the bound would pass, so
// the bound and not the data would decide (cylinder patches of a freeform surface; a nearly flat
// cylinder). Returns each surface's class.
std::vector<std::size_t> radius_classes(const std::vector<SettledSurfaces::Surface>& surfaces,
                                        const RegularityOptions& options) {
  const std::size_t n = surfaces.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return surfaces[a].radius < surfaces[b].radius;
  });
  std::vector<std::size_t> class_of(n);
  std::size_t classes = 0, open = 0;
  // The open class: its first radius, and Σ 1/σ², Σ d/σ², Σ d²/σ² of its radii's differences d
  // from that first one (differences keep the sums exact on CAD radii known to 1e-9).
  double first = 0, information = 0, moment = 0, square = 0;
  std::size_t members = 0;
  for (const std::size_t k : order) {
    const double r = surfaces[k].radius, variance = surfaces[k].radius_variance;
    if (!(variance > 0) ||
        options.significance * std::sqrt(variance) > options.max_radius_difference * r) {
      class_of[k] = classes++;  // a class of its own
      continue;
    }
    const double d = r - first;
    const double joined_information = information + 1 / variance,
                 joined_moment = moment + d / variance, joined_square = square + d * d / variance;
    const double spread = joined_square - joined_moment * joined_moment / joined_information;
    if (members == 0 || r - first > options.max_radius_difference * r ||
        (spread > chi_square_bound(options.significance, members) &&
         !within_tolerance(r - first, options.length_tolerance))) {
      first = r;
      information = 1 / variance;
      moment = square = 0;
      members = 1;
      open = classes++;
      class_of[k] = open;
      continue;
    }
    information = joined_information;
    moment = joined_moment;
    square = joined_square;
    ++members;
    class_of[k] = open;
  }
  return class_of;
}

// Cylinders and spheres of equal radius within the significance (radius_classes) share one
// radius: each component of surfaces joined by a class or by an axis line (a coaxial set) is
// refitted by one joint least squares over its lines' positions, its spheres' centres and its
// radii, the directions kept. As for a coaxial set, a member the joint fit explains worse than
// its own by more than the significance leaves its class, the worst first. Appends the classes
// of two or more to `relations`.
void equalize_radii(const SettledSurfaces& settled, const RegularityOptions& options,
                    std::vector<Primitive>& primitives,
                    const std::vector<std::vector<Vec3>>& points,
                    const std::vector<std::vector<double>>& weights,
                    std::vector<Relation>& relations) {
  const std::vector<SettledSurfaces::Surface>& surfaces = settled.surfaces;
  const std::size_t n = surfaces.size();
  std::vector<std::size_t> class_of = radius_classes(surfaces, options);
  std::vector<std::size_t> class_size(n, 0);
  for (const std::size_t q : class_of) ++class_size[q];
  // Components: union-find over the surfaces, through shared classes and shared lines.
  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](std::size_t k) {
    std::size_t top = k;
    while (parent[top] != top) top = parent[top];
    while (parent[k] != top) k = std::exchange(parent[k], top);
    return top;
  };
  auto join = [&](std::size_t& first, std::size_t k) {
    if (first == n)
      first = k;
    else
      parent[root(k)] = root(first);
  };
  std::vector<std::size_t> first_of_class(n, n), first_on_line(settled.lines.size(), n);
  for (std::size_t k = 0; k < n; ++k) {
    join(first_of_class[class_of[k]], k);
    if (surfaces[k].line != kNoLine) join(first_on_line[surfaces[k].line], k);
  }
  std::vector<std::vector<std::size_t>> components(n);
  for (std::size_t k = 0; k < n; ++k) components[root(k)].push_back(k);
  // A component's lines and radii, numbered in the joint fit; only its own entries are reset, so
  // that many small components cost no more than one large one.
  std::vector<std::size_t> line_index(settled.lines.size(), n), radius_of_class(n, n);
  for (const std::vector<std::size_t>& component : components) {
    if (std::none_of(component.begin(), component.end(),
                     [&](std::size_t k) { return class_size[class_of[k]] >= 2; }))
      continue;
    std::optional<JointFit> fit;
    std::vector<CylinderTerm> terms;
    std::vector<SphereTerm> spheres;
    std::vector<Eigen::Vector3d> directions, sphere_centres;
    std::vector<Eigen::Vector2d> centres;
    std::vector<double> radii;
    // Each member's term: its index among the fit's cylinder terms, or among its spheres.
    std::vector<std::size_t> term_of(component.size());
    while (true) {
      terms.clear();
      spheres.clear();
      directions.clear();
      sphere_centres.clear();
      centres.clear();
      radii.clear();
      for (const std::size_t k : component) {
        if (surfaces[k].line != kNoLine) line_index[surfaces[k].line] = n;
        radius_of_class[class_of[k]] = n;
      }
      for (std::size_t j = 0; j < component.size(); ++j) {
        const SettledSurfaces::Surface& surface = surfaces[component[j]];
        // A class of two or more has one radius, started from its first member's.
        std::size_t& radius = radius_of_class[class_of[component[j]]];
        if (radius == n || class_size[class_of[component[j]]] < 2) {
          radius = radii.size();
          radii.push_back(surface.radius);
        }
        std::size_t line = kNoLine;
        if (surface.line != kNoLine) {
          line = line_index[surface.line];
          if (line == n) {
            line = line_index[surface.line] = directions.size();
            directions.push_back(settled.lines[surface.line].direction);
            centres.push_back(settled.lines[surface.line].centre);
          }
        }
        if (surface.sphere) {
          term_of[j] = spheres.size();
          spheres.push_back({points[surface.cluster], weights[surface.cluster], radius, line});
          sphere_centres.push_back(settled.centres[surface.centre]);
          continue;
        }
        term_of[j] = terms.size();
        terms.push_back({points[surface.cluster], weights[surface.cluster], line, radius});
      }
      fit = fit_cylinders_and_spheres(directions, centres, sphere_centres, radii, terms, spheres,
                                      false);
      if (!fit) break;
      // One test per member: at the significance each, a plate of a hundred equal holes would
      // lose one in four times.
      const std::size_t tested = static_cast<std::size_t>(
          std::count_if(component.begin(), component.end(),
                        [&](std::size_t k) { return class_size[class_of[k]] >= 2; }));
      const double bound = family_significance(options.significance, tested);
      std::size_t worst = component.size();
      double worst_excess = 1;
      for (std::size_t j = 0; j < component.size(); ++j) {
        const SettledSurfaces::Surface& surface = surfaces[component[j]];
        if (class_size[class_of[component[j]]] < 2) continue;
        const double rms = fit->rms[surface.sphere ? terms.size() + term_of[j] : term_of[j]];
        // A sphere's own fit has 4 parameters (2 on a line), a cylinder's (on its direction) 3.
        const int parameters = !surface.sphere ? 3 : surface.line == kNoLine ? 4 : 2;
        const double excess = residual_excess(surface.rms, rms, points[surface.cluster].size(),
                                              bound * bound, parameters, options.length_tolerance);
        if (excess > worst_excess) {
          worst_excess = excess;
          worst = j;
        }
      }
      if (worst == component.size()) break;
      // The worst takes a class of its own, under any unused number.
      --class_size[class_of[component[worst]]];
      const auto free_class = std::find(class_size.begin(), class_size.end(), 0);
      class_of[component[worst]] = static_cast<std::size_t>(free_class - class_size.begin());
      *free_class = 1;
    }
    if (!fit) continue;
    // Written back: the members of classes of two or more, and the surfaces on their lines.
    std::vector<bool> moved_line(settled.lines.size(), false);
    for (const std::size_t k : component)
      if (class_size[class_of[k]] >= 2 && surfaces[k].line != kNoLine)
        moved_line[surfaces[k].line] = true;
    std::map<std::size_t, std::vector<std::size_t>> members_of_class;
    for (std::size_t j = 0; j < component.size(); ++j) {
      const SettledSurfaces::Surface& surface = surfaces[component[j]];
      const bool member = class_size[class_of[component[j]]] >= 2;
      Primitive& primitive = primitives[surface.cluster];
      if (surface.sphere) {
        if (!member && (surface.line == kNoLine || !moved_line[surface.line])) continue;
        primitive.point = to_vec3(fit->sphere_centres[term_of[j]]);
        primitive.radius = fit->radii[spheres[term_of[j]].radius];
      } else {
        if (!moved_line[surface.line]) continue;
        const CylinderTerm& term = terms[term_of[j]];
        place_cylinder(primitive, directions[term.line], fit->centres[term.line],
                       fit->radii[term.radius]);
      }
      if (member) members_of_class[class_of[component[j]]].push_back(surface.cluster);
    }
    for (auto& [unused, members] : members_of_class) {
      Relation& relation = relations.emplace_back();
      relation.kind = Relation::Kind::EqualRadius;
      std::sort(members.begin(), members.end());
      relation.members = std::move(members);
    }
  }
}

// Moves directions a and b (unit) to be orthogonal, each along its own covariance: the
// least-squares correction, repeated until the cosine is below 1e-15. False when it does not get
// there.
bool make_orthogonal(Eigen::Vector3d& a, const Eigen::Matrix3d& covariance_a, Eigen::Vector3d& b,
                     const Eigen::Matrix3d& covariance_b) {
  for (int step = 0; step < 100; ++step) {
    const double cosine = a.dot(b);
    if (std::abs(cosine) <= 1e-15) return true;
    const Eigen::Vector3d move_a = covariance_a * b, move_b = covariance_b * a;
    const double scale = cosine / (b.dot(move_a) + a.dot(move_b));
    if (!std::isfinite(scale)) return false;
    a = (a - scale * move_a).normalized();
    b = (b - scale * move_b).normalized();
  }
  return false;
}

// The most groups a frame (a component closing a triangle of right angles) is solved over.
constexpr std::size_t kLargestFrame = 16;

// Pairs of direction groups at right angles within the significance (or the angle tolerance),
// made exactly so.
//
// Pairs are taken by increasing score, each scored again when it comes up on the directions the
// pairs kept before it left (a kept pair moves its component's directions), so pairs up to twice
// the significance wait in the queue. The kept pairs join the
// groups into components. In a component of at most kLargestFrame groups (a part's frames: its
// directions at right angles) every constraint is met by least squares from the measured
// directions, each moved along its covariance (sweeps of make_orthogonal), and a pair within a
// component is tried only when it closes a triangle (two directions orthogonal to a third, made
// orthogonal to each other); other cycles need not be satisfiable. A larger component is a tree
// of chance right angles between a freeform surface's many planes (bunny00: 486 pairs among 488
// groups): a pair joining two of them is met by its own two directions, each side turning
// rigidly with its own, so it costs O(G), not sweeps over every constraint. Either way the pair
// is kept only when no direction ends beyond the significance (or the angle tolerance) of its
// measurement. Returns the kept pairs (indices into `groups`, first < second), in increasing order.
std::vector<std::pair<std::size_t, std::size_t>> orthogonalize(std::vector<DirectionGroup>& groups,
                                                               const RegularityOptions& options) {
  using Pair = std::pair<std::size_t, std::size_t>;
  const std::size_t count = groups.size();
  const double max_tilt = options.max_angle_degrees * std::numbers::pi / 180;
  const double significance2 = options.significance * options.significance;
  std::vector<Eigen::Vector3d> measured;
  measured.reserve(count);
  for (const DirectionGroup& group : groups) measured.push_back(group.direction);
  std::vector<Eigen::Vector3d> solved = measured;
  auto score = [&](std::size_t i, std::size_t j) {
    const Eigen::Vector3d &a = solved[i], &b = solved[j];
    const double cosine = a.dot(b);
    const double from_right_angle = std::abs(std::asin(std::clamp(cosine, -1.0, 1.0)));
    if (from_right_angle > max_tilt) return std::numeric_limits<double>::infinity();
    return tolerated(
        cosine * cosine / (b.dot(groups[i].covariance * b) + a.dot(groups[j].covariance * a)),
        significance2, from_right_angle, options.angle_tolerance);
  };
  // Min-queue of (score, i, j); a score is that of the directions when it was computed.
  using Entry = std::tuple<double, std::size_t, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (std::size_t i = 0; i < count; ++i)
    for (std::size_t j = i + 1; j < count; ++j)
      if (const double value = score(i, j); value <= 4 * significance2) queue.emplace(value, i, j);

  std::vector<std::vector<std::size_t>> adjacent(count);  // kept pairs, by group
  std::vector<std::size_t> component_of(count);
  std::vector<std::vector<std::size_t>> members(count);
  for (std::size_t g = 0; g < count; ++g) {
    component_of[g] = g;
    members[g] = {g};
  }
  std::vector<Pair> kept;
  std::vector<Eigen::Vector3d> moved;
  while (!queue.empty()) {
    // Not a structured binding: clang 14 cannot capture one in the lambdas below.
    const double stale = std::get<0>(queue.top());
    const std::size_t i = std::get<1>(queue.top()), j = std::get<2>(queue.top());
    queue.pop();
    const double value = score(i, j);
    if (!(value <= 4 * significance2)) continue;
    // Scored again: wait for the pairs that now come first, or for good when it has not moved.
    if (value > stale || (!queue.empty() && value > std::get<0>(queue.top()))) {
      if (value > stale) queue.emplace(value, i, j);
      continue;
    }
    if (value > significance2) continue;
    const std::size_t ci = component_of[i], cj = component_of[j];
    std::vector<std::size_t> component = members[ci];
    if (ci != cj) component.insert(component.end(), members[cj].begin(), members[cj].end());
    moved.clear();
    if (component.size() <= kLargestFrame) {
      // Within a component, only a pair that closes a triangle of right angles.
      if (ci == cj && std::none_of(adjacent[i].begin(), adjacent[i].end(), [&](std::size_t k) {
            return std::find(adjacent[j].begin(), adjacent[j].end(), k) != adjacent[j].end();
          }))
        continue;
      // Least squares from the measurements: sweeps of make_orthogonal over every constraint.
      std::vector<Pair> constraints{{i, j}};
      for (const std::size_t g : component)
        for (const std::size_t h : adjacent[g])
          if (g < h) constraints.emplace_back(g, h);
      std::vector<Eigen::Vector3d> d = solved;
      for (const std::size_t g : component) d[g] = measured[g];
      bool converged = false;
      for (int sweep = 0; sweep < 200 && !converged; ++sweep) {
        converged = true;
        for (const auto& [a, b] : constraints)
          if (std::abs(d[a].dot(d[b])) > 1e-15) {
            converged = false;
            make_orthogonal(d[a], groups[a].covariance, d[b], groups[b].covariance);
          }
      }
      if (!converged) continue;
      for (const std::size_t g : component) moved.push_back(d[g]);
    } else {
      // A large component is a tree (no triangle is closed in one): the pair's two directions
      // meet, and each side turns rigidly with its own.
      if (ci == cj) continue;
      Eigen::Vector3d a = solved[i], b = solved[j];
      if (!make_orthogonal(a, groups[i].covariance, b, groups[j].covariance)) continue;
      const Eigen::Quaterniond turn_i = Eigen::Quaterniond::FromTwoVectors(solved[i], a);
      const Eigen::Quaterniond turn_j = Eigen::Quaterniond::FromTwoVectors(solved[j], b);
      for (const std::size_t g : component)
        moved.push_back(g == i ? a
                        : g == j
                            ? b
                            : ((component_of[g] == ci ? turn_i : turn_j) * solved[g]).normalized());
    }
    bool within = true;
    for (std::size_t k = 0; within && k < component.size(); ++k) {
      const Eigen::Vector3d tilt = moved[k] - measured[component[k]];
      within = tilt.dot(groups[component[k]].information * tilt) <= significance2 ||
               within_tolerance(angle_between_lines(moved[k], measured[component[k]]),
                                options.angle_tolerance);
    }
    if (!within) continue;
    for (std::size_t k = 0; k < component.size(); ++k) solved[component[k]] = moved[k];
    kept.emplace_back(i, j);
    adjacent[i].push_back(j);
    adjacent[j].push_back(i);
    if (ci != cj) {
      for (const std::size_t g : members[cj]) component_of[g] = ci;
      members[ci] = std::move(component);
      members[cj].clear();
    }
  }
  for (std::size_t g = 0; g < count; ++g) groups[g].direction = solved[g];
  std::sort(kept.begin(), kept.end());
  return kept;
}

// Groups the right angles made one direction. On an exact CAD mesh directions are known to a
// tiny fraction of a degree, and two groups of faces the part means to be parallel can differ by
// more than that before the right angles; each then made orthogonal to the same two others, they
// end with one direction to round-off. They are one group: the first keeps its direction and
// takes the other's members, information, coplanar sets and right angles (`orthogonal`, indices
// into `groups`, renumbered; the emptied group keeps none).
void merge_parallel_groups(std::vector<DirectionGroup>& groups,
                           std::vector<std::pair<std::size_t, std::size_t>>& orthogonal,
                           std::vector<std::vector<std::vector<std::size_t>>>& coplanar) {
  std::vector<std::size_t> merged_into(groups.size());
  std::iota(merged_into.begin(), merged_into.end(), std::size_t{0});
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (merged_into[g] != g) continue;
    DirectionGroup& kept = groups[g];
    bool merged = false;
    for (std::size_t h = g + 1; h < groups.size(); ++h) {
      if (merged_into[h] != h ||
          !(kept.direction.cross(groups[h].direction).norm() <= kSameDirection))
        continue;
      merged_into[h] = g;
      merged = true;
      kept.members.insert(kept.members.end(), groups[h].members.begin(), groups[h].members.end());
      groups[h].members.clear();
      kept.information += groups[h].information;
      coplanar[g].insert(coplanar[g].end(), coplanar[h].begin(), coplanar[h].end());
      coplanar[h].clear();
    }
    if (!merged) continue;
    std::sort(kept.members.begin(), kept.members.end());
    // The tilt's covariance from the joint information across the kept direction.
    const Eigen::Matrix3d across =
        Eigen::Matrix3d::Identity() - kept.direction * kept.direction.transpose();
    kept.covariance = tilt_covariance(
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(across * kept.information * across));
  }
  for (auto& [i, j] : orthogonal) {
    i = merged_into[i];
    j = merged_into[j];
    if (i > j) std::swap(i, j);
  }
  std::sort(orthogonal.begin(), orthogonal.end());
  orthogonal.erase(std::unique(orthogonal.begin(), orthogonal.end()), orthogonal.end());
}

// ClusterRelation::deviation of `related`: how far the clusters' own fits (`own`) were from it;
// `shared` holds the fits that make it exact. Degrees for directions, the points' units for
// lengths.
double deviation(const ClusterRelation& related, std::span<const Primitive> own,
                 std::span<const Primitive> shared) {
  using Kind = ClusterRelation::Kind;
  const std::vector<std::uint32_t>& members = related.clusters;
  const auto axis = [&](std::uint32_t c) { return to_eigen(own[c].axis); };
  const auto point = [&](std::uint32_t c) { return to_eigen(own[c].point); };
  constexpr double kDegrees = 180 / std::numbers::pi;
  double largest = 0;
  switch (related.kind) {
    case Kind::Parallel:
      for (const std::uint32_t c : members)
        largest = std::max(largest, angle_between_lines(axis(c), to_eigen(shared[c].axis)));
      return largest * kDegrees;
    case Kind::Orthogonal:
      for (const std::uint32_t a : members)
        for (const std::uint32_t b : related.orthogonal_to)
          largest = std::max(largest, std::numbers::pi / 2 - angle_between_lines(axis(a), axis(b)));
      return largest * kDegrees;
    case Kind::Coaxial: {
      // The shared line: a cylinder's, else (spheres alone) through the two centres farthest apart.
      Eigen::Vector3d on_line = Eigen::Vector3d::Zero(), along = Eigen::Vector3d::Zero();
      const auto cylinder = std::find_if(members.begin(), members.end(), [&](std::uint32_t c) {
        return shared[c].type == PrimitiveType::Cylinder;
      });
      if (cylinder != members.end()) {
        on_line = to_eigen(shared[*cylinder].point);
        along = to_eigen(shared[*cylinder].axis).normalized();
      } else {
        for (const std::uint32_t a : members)
          for (const std::uint32_t b : members) {
            const Eigen::Vector3d apart = to_eigen(shared[b].point) - to_eigen(shared[a].point);
            if (apart.norm() > along.norm()) {
              on_line = to_eigen(shared[a].point);
              along = apart;
            }
          }
        if (!(along.norm() > 0)) return 0;
        along.normalize();
      }
      for (const std::uint32_t c : members)
        largest = std::max(largest, (point(c) - on_line).cross(along).norm());
      return largest;
    }
    case Kind::EqualRadius: {
      const auto [smallest, biggest] = std::minmax_element(
          members.begin(), members.end(),
          [&](std::uint32_t a, std::uint32_t b) { return own[a].radius < own[b].radius; });
      return own[*biggest].radius - own[*smallest].radius;
    }
    case Kind::Coplanar: {
      const Eigen::Vector3d normal = to_eigen(shared[members[0]].axis);
      const Eigen::Vector3d on_plane = to_eigen(shared[members[0]].point);
      for (const std::uint32_t c : members)
        largest = std::max(largest, std::abs(normal.dot(point(c) - on_plane)));
      return largest;
    }
    case Kind::Tangent: {
      std::uint32_t c = members[0], p = members[1];
      if (own[c].type != PrimitiveType::Cylinder) std::swap(c, p);
      if (own[p].type == PrimitiveType::Plane)
        return std::abs(std::abs(axis(p).dot(point(c) - point(p))) - own[c].radius);
      // Two cylinders: the distance of the smaller one's axis, at its point, from the larger's
      // line, against the sum or the difference of their radii, whichever is nearer.
      if (own[c].radius > own[p].radius) std::swap(c, p);
      const double distance = distance_across(point(c) - point(p), axis(p).normalized());
      return std::abs(nearest_circle_contact(distance, own[c].radius, own[p].radius).gap);
    }
  }
  return 0;
}

}  // namespace

std::vector<Relation> regularize(std::vector<Primitive>& primitives,
                                 const std::vector<std::vector<Vec3>>& points,
                                 const std::vector<std::vector<double>>& weights,
                                 const RegularityOptions& options) {
  std::vector<Relation> relations;
  std::vector<Oriented> items;
  for (std::size_t c = 0; c < primitives.size(); ++c) {
    std::optional<Oriented> item;
    if (primitives[c].type == PrimitiveType::Plane)
      item = oriented_plane(c, points[c]);
    else if (primitives[c].type == PrimitiveType::Cylinder)
      item = oriented_cylinder(c, primitives[c], points[c]);
    if (item && std::isfinite(item->variance) && item->variance > 0) items.push_back(*item);
  }
  std::vector<DirectionGroup> groups = group_directions(items, options);
  // Each group's coplanar sets and coaxial sets, found before the directions are made orthogonal:
  // each counts as one plane or one line in its group's direction.
  std::vector<std::vector<std::vector<std::size_t>>> coplanar(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g) {
    DirectionGroup& group = groups[g];
    if (group.members.size() < 2) continue;
    bool counted = false;
    std::vector<AlignedPlane> planes;
    const auto is_plane = [&](std::size_t i) {
      return primitives[items[i].cluster].type == PrimitiveType::Plane;
    };
    if (options.coplanar &&
        std::count_if(group.members.begin(), group.members.end(), is_plane) >= 2)
      for (const std::size_t i : group.members) {
        const std::size_t c = items[i].cluster;
        if (primitives[c].type != PrimitiveType::Plane) continue;
        if (const std::optional<AlignedPlane> plane =
                aligned_plane(c, group.direction, points[c], weights[c]))
          planes.push_back(*plane);
      }
    if (planes.size() >= 2) {
      coplanar[g] = coplanar_sets(group.covariance, std::move(planes), options);
      counted = count_coplanar_as_one(group, items, coplanar[g], points);
    }
    if (count_coaxial_as_one(group, items, primitives, points, weights, options)) counted = true;
    if (!counted) continue;
    const Eigen::Vector3d before = group.direction;
    form_direction(group);
    if (group.direction.dot(before) < 0) group.direction = -group.direction;
  }
  std::vector<std::pair<std::size_t, std::size_t>> orthogonal;
  if (options.orthogonal) {
    orthogonal = orthogonalize(groups, options);
    merge_parallel_groups(groups, orthogonal, coplanar);
  }
  std::vector<bool> constrained(groups.size(), false);
  for (const auto& [i, j] : orthogonal) constrained[i] = constrained[j] = true;
  // The clusters each group refitted, for the orthogonal relations.
  std::vector<std::vector<std::size_t>> refitted(groups.size());
  SettledSurfaces settled;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const DirectionGroup& group = groups[g];
    if (group.members.size() < 2 && !constrained[g]) continue;
    std::vector<AlignedCylinder> cylinders;
    Relation parallel;
    for (const std::size_t i : group.members) {
      const std::size_t c = items[i].cluster;
      Primitive& primitive = primitives[c];
      if (primitive.type == PrimitiveType::Plane) {
        if (align_plane(primitive, group.direction, points[c], weights[c]))
          parallel.members.push_back(c);
        continue;
      }
      if (std::optional<AlignedCylinder> cylinder =
              aligned_cylinder(c, primitive, group.direction, points, weights)) {
        cylinders.push_back(std::move(*cylinder));
        parallel.members.push_back(c);
      }
    }
    std::sort(parallel.members.begin(), parallel.members.end());
    refitted[g] = parallel.members;
    if (parallel.members.size() >= 2) relations.push_back(std::move(parallel));
    for (const std::vector<std::size_t>& set : coplanar[g])
      share_one_plane(group.direction, set, primitives, weights, relations);
    align_cylinders(group.direction, group.covariance, std::move(cylinders), options, primitives,
                    points, weights, relations, settled);
  }
  if (options.equal_radii || options.spheres_on_axes) {
    // The cylinders no direction relation refitted take part too, each on its own axis (fitted
    // again with it, for its radius's uncertainty; written back only if it joins a relation), and
    // the spheres, each fitted again on its own.
    std::vector<bool> is_settled(primitives.size(), false);
    for (const SettledSurfaces::Surface& surface : settled.surfaces)
      is_settled[surface.cluster] = true;
    for (const Oriented& item : items) {
      const std::size_t c = item.cluster;
      if (primitives[c].type != PrimitiveType::Cylinder || is_settled[c]) continue;
      if (const std::optional<CoaxialFit> fit =
              fit_alone(primitives[c], item.direction, points[c], weights[c])) {
        settled.surfaces.push_back({c, false, settled.lines.size(), 0, fit->radii[0],
                                    fit->radius_variances[0], fit->rms[0]});
        settled.lines.push_back({item.direction, fit->centre, fit->centre_covariance, kNoRelation,
                                 middle_along(item.direction, {&c, 1}, points, weights),
                                 item.covariance});
      }
    }
    for (std::size_t c = 0; c < primitives.size(); ++c) {
      if (primitives[c].type != PrimitiveType::Sphere || points[c].empty()) continue;
      const Eigen::Vector3d centre = to_eigen(primitives[c].point);
      const SphereTerm term{points[c], weights[c], 0};
      if (const std::optional<JointFit> fit = fit_cylinders_and_spheres(
              {}, {}, {&centre, 1}, {&primitives[c].radius, 1}, {}, {&term, 1}, true)) {
        settled.surfaces.push_back({c, true, kNoLine, settled.centres.size(), fit->radii[0],
                                    fit->covariance(3, 3), fit->rms[0]});
        settled.centres.push_back(fit->sphere_centres[0]);
        settled.centre_covariances.emplace_back(fit->covariance.topLeftCorner<3, 3>());
      }
    }
    if (options.spheres_on_axes) {
      centre_spheres_on_axes(settled, options, primitives, points, weights, relations);
      line_up_spheres(settled, groups, refitted, options, primitives, points, weights, relations);
    }
    if (options.equal_radii)
      equalize_radii(settled, options, primitives, points, weights, relations);
  }
  std::vector<Relation> tangents;
  if (options.tangency)
    make_tangent(groups, orthogonal, refitted, options, primitives, points, weights, relations,
                 tangents);
  std::vector<Relation> right_angles;
  for (const auto& [i, j] : orthogonal) {
    if (refitted[i].empty() || refitted[j].empty()) continue;
    Relation& relation = right_angles.emplace_back();
    relation.kind = Relation::Kind::Orthogonal;
    // The group of the lower cluster first.
    const bool swap = refitted[j].front() < refitted[i].front();
    relation.members = swap ? refitted[j] : refitted[i];
    relation.others = swap ? refitted[i] : refitted[j];
  }
  std::sort(right_angles.begin(), right_angles.end(), [](const Relation& a, const Relation& b) {
    return std::tie(a.members, a.others) < std::tie(b.members, b.others);
  });
  relations.insert(relations.end(), right_angles.begin(), right_angles.end());
  relations.insert(relations.end(), tangents.begin(), tangents.end());
  return relations;
}

void sort_relations(std::vector<ClusterRelation>& relations) {
  std::sort(relations.begin(), relations.end(), [](const auto& a, const auto& b) {
    return a.kind != b.kind           ? a.kind < b.kind
           : a.clusters != b.clusters ? a.clusters < b.clusters
                                      : a.orthogonal_to < b.orthogonal_to;
  });
}

void keep_inliers(const Primitive& primitive, std::span<const Vec3> points,
                  std::span<const double> weights, double threshold, double floor,
                  std::vector<Vec3>& kept_points, std::vector<double>& kept_weights) {
  std::vector<double> residuals;
  residuals.reserve(points.size());
  for (const Vec3& p : points) residuals.push_back(primitive.distance(p));
  std::vector<double> sorted = residuals;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double limit = std::max(threshold * 1.4826 * sorted[sorted.size() / 2], floor);
  kept_points.clear();
  kept_weights.clear();
  for (std::size_t i = 0; i < points.size(); ++i)
    if (residuals[i] <= limit) {
      kept_points.push_back(points[i]);
      kept_weights.push_back(weights[i]);
    }
}

std::vector<ClusterRelation> regularize_kept(std::vector<Primitive>& primitives,
                                             const std::vector<std::vector<Vec3>>& inlier_points,
                                             const std::vector<std::vector<double>>& inlier_weights,
                                             const RegularityOptions& options) {
  const std::vector<Primitive> own = primitives;
  std::vector<ClusterRelation> relations;
  for (const Relation& relation : regularize(primitives, inlier_points, inlier_weights, options)) {
    ClusterRelation& related = relations.emplace_back();
    related.kind = relation.kind;
    for (const std::size_t c : relation.members)
      related.clusters.push_back(static_cast<std::uint32_t>(c));
    for (const std::size_t c : relation.others)
      related.orthogonal_to.push_back(static_cast<std::uint32_t>(c));
    related.deviation = deviation(related, own, primitives);
  }
  sort_relations(relations);
  return relations;
}

std::vector<ClusterRelation> regularize_inliers(std::vector<Primitive>& primitives,
                                                const std::vector<std::vector<Vec3>>& points,
                                                const std::vector<std::vector<double>>& weights,
                                                double outlier_threshold, double floor,
                                                const RegularityOptions& options) {
  std::vector<std::vector<Vec3>> inlier_points(primitives.size());
  std::vector<std::vector<double>> inlier_weights(primitives.size());
  for (std::size_t c = 0; c < primitives.size(); ++c)
    if (!points[c].empty())
      keep_inliers(primitives[c], points[c], weights[c], outlier_threshold, floor, inlier_points[c],
                   inlier_weights[c]);
  return regularize_kept(primitives, inlier_points, inlier_weights, options);
}

}  // namespace primseg::detail
