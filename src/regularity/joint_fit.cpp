// Joint geometric fits of cylinders and spheres on shared axis lines and radii.
#include "regularity/stages.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "eigen_conversions.hpp"
#include "orthonormal_pair.hpp"

namespace primseg::detail {

void place_cylinder(Primitive& cylinder, const Eigen::Vector3d& direction,
                    const Eigen::Vector2d& centre, double radius) {
  const auto [u, v] = orthonormal_pair(direction);
  cylinder.axis = to_vec3(direction.dot(to_eigen(cylinder.axis)) < 0 ? -direction : direction);
  const Eigen::Vector3d on_axis = centre.x() * u + centre.y() * v;
  cylinder.point = to_vec3(on_axis + direction * direction.dot(to_eigen(cylinder.point) - on_axis));
  cylinder.radius = radius;
}

namespace {

// The solution of A δ = b, a symmetric system, by LDLT in a frame where A's and b's largest entries
// are scaled into [1/2, 1) by powers of two. Eigen's LDLT does not scale exactly with its input: a
// nearly singular system (a nearly flat cylinder's centre and radius) multiplied by 64 gave
// solutions that differed from 64 times the first in the sixth digit, so the same part modelled in
// other units settled on another radius (fuzz_tools). Scaled so, both are the same system.
Eigen::VectorXd solve_in_unit_scale(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  int a_exponent = 0, b_exponent = 0;
  if (a.size() > 0) std::frexp(a.cwiseAbs().maxCoeff(), &a_exponent);
  if (b.size() > 0) std::frexp(b.cwiseAbs().maxCoeff(), &b_exponent);
  const Eigen::MatrixXd unit_a = a.unaryExpr([&](double x) { return std::ldexp(x, -a_exponent); });
  const Eigen::VectorXd unit_b = b.unaryExpr([&](double x) { return std::ldexp(x, -b_exponent); });
  return unit_a.ldlt().solve(unit_b).unaryExpr(
      [&](double x) { return std::ldexp(x, b_exponent - a_exponent); });
}

// The normal equations of fit_cylinders_and_spheres() at x = (line centres 2 each, free sphere
// centres 3 each, positions of the sphere centres on a line along it, radii), by blocks: each
// line's own 2x2, each term's coupling of its line and its radius, each radius's diagonal (radii
// never couple with each other, lines never with lines). A sphere centre's 3x3 block is over its
// position, or over its line's centre and its position along it; each of its spheres couples it
// with that sphere's radius.
class JointSystem {
 public:
  JointSystem(std::span<const Eigen::Vector3d> directions, std::span<const Eigen::Vector2d> centres,
              std::span<const Eigen::Vector3d> sphere_centres, std::span<const double> radii,
              std::span<const CylinderTerm> terms, std::span<const SphereTerm> spheres);

  // The blocks at x, each point's residual weighted or not; the unweighted Σ e² over all points.
  double linearise(bool weighted);
  // The Gauss–Newton step from the blocks.
  Eigen::VectorXd step();
  // The whole normal matrix and gradient of the blocks.
  void whole_system(Eigen::MatrixXd& normal, Eigen::VectorXd& gradient) const;
  // The fit at x, with the residuals of the last linearise(); the covariance from its normal
  // matrix times the residual variance of `squares` if asked. Nothing when it is not finite.
  std::optional<JointFit> result(double squares, bool with_covariance) const;

  Eigen::VectorXd x;
  std::size_t count = 0;  // points with a residual, at the last linearise()

 private:
  // The radii's Schur complement S = D − Σ Bₗᵀ Aₗ⁻¹ Bₗ, then each line's and centre's position.
  Eigen::VectorXd step_by_blocks();

  std::span<const Eigen::Vector3d> directions_;
  std::span<const CylinderTerm> terms_;
  std::span<const SphereTerm> spheres_;
  Eigen::Index lines_, radius_count_, first_radius_, size_;
  // Per sphere centre: its line (kNoLine: free), its first parameter, its spheres.
  std::vector<std::size_t> centre_line_;
  std::vector<Eigen::Index> centre_offset_;
  std::vector<std::vector<std::size_t>> spheres_of_centre_;
  // The points in the plane orthogonal to their line's direction, once for every iteration; a
  // sphere's with its centre on a line in the line's frame (u, v, direction).
  std::vector<std::vector<Eigen::Vector2d>> projected_;
  std::vector<std::vector<Eigen::Vector3d>> sphere_local_;
  std::vector<std::vector<std::size_t>> terms_on_line_, centres_on_line_;
  std::vector<Eigen::Matrix2d> line_block_;
  std::vector<Eigen::Vector2d> coupling_, line_gradient_;
  std::vector<Eigen::Matrix3d> centre_block_;  // per centre
  std::vector<Eigen::Vector3d> centre_gradient_;
  std::vector<Eigen::Vector3d> sphere_coupling_;  // per sphere, with its radius
  Eigen::VectorXd radius_diagonal_, radius_gradient_;
  // Per cylinder term, then per sphere.
  std::vector<double> term_squares_;
  std::vector<std::size_t> term_count_;
  // step_by_blocks()'s: per line, with the positions of its centres along it eliminated, its
  // block's inverse, its gradient, and the coupling of each of its terms (cylinders, then
  // spheres) with that term's radius; per free centre, its block's inverse.
  std::vector<Eigen::Matrix2d> inverse_;
  std::vector<Eigen::Vector2d> reduced_gradient_;
  std::vector<std::vector<std::pair<Eigen::Index, Eigen::Vector2d>>> reduced_coupling_;
  std::vector<Eigen::Matrix3d> centre_inverse_;
};

JointSystem::JointSystem(std::span<const Eigen::Vector3d> directions,
                         std::span<const Eigen::Vector2d> centres,
                         std::span<const Eigen::Vector3d> sphere_centres,
                         std::span<const double> radii, std::span<const CylinderTerm> terms,
                         std::span<const SphereTerm> spheres)
    : directions_(directions),
      terms_(terms),
      spheres_(spheres),
      lines_(static_cast<Eigen::Index>(centres.size())),
      radius_count_(static_cast<Eigen::Index>(radii.size())),
      centre_line_(sphere_centres.size(), kNoLine),
      centre_offset_(sphere_centres.size()),
      spheres_of_centre_(sphere_centres.size()),
      projected_(terms.size()),
      sphere_local_(spheres.size()),
      terms_on_line_(centres.size()),
      centres_on_line_(centres.size()),
      line_block_(centres.size()),
      coupling_(terms.size()),
      line_gradient_(centres.size()),
      centre_block_(sphere_centres.size()),
      centre_gradient_(sphere_centres.size()),
      sphere_coupling_(spheres.size()),
      radius_diagonal_(radius_count_),
      radius_gradient_(radius_count_),
      term_squares_(terms.size() + spheres.size()),
      term_count_(terms.size() + spheres.size()),
      inverse_(centres.size()),
      reduced_gradient_(centres.size()),
      reduced_coupling_(centres.size()),
      centre_inverse_(sphere_centres.size()) {
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    centre_line_[spheres[s].centre] = spheres[s].line;
    spheres_of_centre_[spheres[s].centre].push_back(s);
  }
  const Eigen::Index free_centres = std::count(centre_line_.begin(), centre_line_.end(), kNoLine);
  Eigen::Index next_free = 2 * lines_, next_on_line = 2 * lines_ + 3 * free_centres;
  for (std::size_t c = 0; c < sphere_centres.size(); ++c) {
    const std::size_t l = centre_line_[c];
    centre_offset_[c] = l == kNoLine ? std::exchange(next_free, next_free + 3) : next_on_line++;
    if (l != kNoLine) centres_on_line_[l].push_back(c);
  }
  first_radius_ = next_on_line;
  size_ = first_radius_ + radius_count_;
  x.resize(size_);
  for (Eigen::Index l = 0; l < lines_; ++l) x.segment<2>(2 * l) = centres[l];
  for (std::size_t c = 0; c < sphere_centres.size(); ++c) {
    if (centre_line_[c] == kNoLine)
      x.segment<3>(centre_offset_[c]) = sphere_centres[c];
    else
      x(centre_offset_[c]) = directions[centre_line_[c]].dot(sphere_centres[c]);
  }
  for (Eigen::Index q = 0; q < radius_count_; ++q) x(first_radius_ + q) = radii[q];
  for (std::size_t k = 0; k < terms.size(); ++k) {
    const auto [u, v] = orthonormal_pair(directions[terms[k].line]);
    for (const Vec3& p : terms[k].points)
      projected_[k].emplace_back(u.dot(to_eigen(p)), v.dot(to_eigen(p)));
    terms_on_line_[terms[k].line].push_back(k);
  }
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    const std::size_t l = spheres[s].line;
    if (l == kNoLine) continue;
    const Eigen::Vector3d& direction = directions[l];
    const auto [u, v] = orthonormal_pair(direction);
    for (const Vec3& p : spheres[s].points)
      sphere_local_[s].emplace_back(u.dot(to_eigen(p)), v.dot(to_eigen(p)),
                                    direction.dot(to_eigen(p)));
  }
}

double JointSystem::linearise(bool weighted) {
  std::fill(line_block_.begin(), line_block_.end(), Eigen::Matrix2d::Zero());
  std::fill(coupling_.begin(), coupling_.end(), Eigen::Vector2d::Zero());
  std::fill(line_gradient_.begin(), line_gradient_.end(), Eigen::Vector2d::Zero());
  std::fill(centre_block_.begin(), centre_block_.end(), Eigen::Matrix3d::Zero());
  std::fill(centre_gradient_.begin(), centre_gradient_.end(), Eigen::Vector3d::Zero());
  std::fill(sphere_coupling_.begin(), sphere_coupling_.end(), Eigen::Vector3d::Zero());
  radius_diagonal_.setZero();
  radius_gradient_.setZero();
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
    radius_diagonal_(q) += w;
    position_gradient += w * j * e;
    radius_gradient_(q) -= w * e;
    squares += e * e;
    term_squares_[k] += e * e;
    ++term_count_[k];
    ++count;
  };
  for (std::size_t k = 0; k < terms_.size(); ++k) {
    const std::size_t l = terms_[k].line;
    const Eigen::Index q = static_cast<Eigen::Index>(terms_[k].radius);
    const Eigen::Vector2d centre = x.segment<2>(2 * static_cast<Eigen::Index>(l));
    const double radius = x(first_radius_ + q);
    term_squares_[k] = 0;
    term_count_[k] = 0;
    for (std::size_t i = 0; i < projected_[k].size(); ++i)
      add_point((projected_[k][i] - centre).eval(), radius, weighted ? terms_[k].weights[i] : 1.0,
                line_block_[l], coupling_[k], line_gradient_[l], q, k);
  }
  for (std::size_t s = 0; s < spheres_.size(); ++s) {
    const Eigen::Index q = static_cast<Eigen::Index>(spheres_[s].radius);
    const std::size_t c = spheres_[s].centre;
    const Eigen::Index offset = centre_offset_[c];
    const double radius = x(first_radius_ + q);
    const std::size_t k = terms_.size() + s;
    term_squares_[k] = 0;
    term_count_[k] = 0;
    if (spheres_[s].line == kNoLine) {
      const Eigen::Vector3d centre = x.segment<3>(offset);
      for (std::size_t i = 0; i < spheres_[s].points.size(); ++i)
        add_point((to_eigen(spheres_[s].points[i]) - centre).eval(), radius,
                  weighted ? spheres_[s].weights[i] : 1.0, centre_block_[c], sphere_coupling_[s],
                  centre_gradient_[c], q, k);
    } else {
      const Eigen::Index l = 2 * static_cast<Eigen::Index>(spheres_[s].line);
      const Eigen::Vector3d centre(x(l), x(l + 1), x(offset));
      for (std::size_t i = 0; i < sphere_local_[s].size(); ++i)
        add_point((sphere_local_[s][i] - centre).eval(), radius,
                  weighted ? spheres_[s].weights[i] : 1.0, centre_block_[c], sphere_coupling_[s],
                  centre_gradient_[c], q, k);
    }
  }
  return squares;
}

void JointSystem::whole_system(Eigen::MatrixXd& normal, Eigen::VectorXd& gradient) const {
  normal.setZero(size_, size_);
  gradient.resize(size_);
  for (Eigen::Index l = 0; l < lines_; ++l) {
    normal.block<2, 2>(2 * l, 2 * l) = line_block_[static_cast<std::size_t>(l)];
    gradient.segment<2>(2 * l) = line_gradient_[static_cast<std::size_t>(l)];
  }
  for (std::size_t k = 0; k < terms_.size(); ++k)
    normal.block<2, 1>(2 * static_cast<Eigen::Index>(terms_[k].line),
                       first_radius_ + static_cast<Eigen::Index>(terms_[k].radius)) += coupling_[k];
  for (std::size_t c = 0; c < centre_line_.size(); ++c) {
    const Eigen::Index o = centre_offset_[c];
    const Eigen::Matrix3d& block = centre_block_[c];
    if (centre_line_[c] == kNoLine) {
      normal.block<3, 3>(o, o) = block;
      gradient.segment<3>(o) = centre_gradient_[c];
      for (const std::size_t s : spheres_of_centre_[c])
        normal.block<3, 1>(o, first_radius_ + static_cast<Eigen::Index>(spheres_[s].radius)) +=
            sphere_coupling_[s];
      continue;
    }
    const Eigen::Index l = 2 * static_cast<Eigen::Index>(centre_line_[c]);
    normal.block<2, 2>(l, l) += block.topLeftCorner<2, 2>();
    normal.block<2, 1>(l, o) = block.block<2, 1>(0, 2);
    normal.block<1, 2>(o, l) = block.block<1, 2>(2, 0);
    normal(o, o) = block(2, 2);
    gradient.segment<2>(l) += centre_gradient_[c].head<2>();
    gradient(o) = centre_gradient_[c](2);
    for (const std::size_t s : spheres_of_centre_[c]) {
      const Eigen::Index q = first_radius_ + static_cast<Eigen::Index>(spheres_[s].radius);
      normal.block<2, 1>(l, q) += sphere_coupling_[s].head<2>();
      normal(o, q) += sphere_coupling_[s](2);
    }
  }
  normal.diagonal().tail(radius_count_) = radius_diagonal_;
  gradient.tail(radius_count_) = radius_gradient_;
  for (Eigen::Index row = first_radius_; row < size_; ++row)
    for (Eigen::Index col = 0; col < row; ++col) normal(row, col) = normal(col, row);
}

Eigen::VectorXd JointSystem::step() {
  if (lines_ == 1 && spheres_.empty()) {
    Eigen::MatrixXd normal;
    Eigen::VectorXd gradient;
    whole_system(normal, gradient);
    return solve_in_unit_scale(normal, -gradient);
  }
  return step_by_blocks();
}

Eigen::VectorXd JointSystem::step_by_blocks() {
  Eigen::VectorXd delta(size_);
  Eigen::MatrixXd schur = radius_diagonal_.asDiagonal();
  Eigen::VectorXd right = -radius_gradient_;
  const auto radius_of = [&](std::size_t s) {
    return static_cast<Eigen::Index>(spheres_[s].radius);
  };
  for (std::size_t l = 0; l < line_block_.size(); ++l) {
    Eigen::Matrix2d block = line_block_[l];
    reduced_gradient_[l] = line_gradient_[l];
    std::vector<std::pair<Eigen::Index, Eigen::Vector2d>>& couplings = reduced_coupling_[l];
    couplings.clear();
    for (const std::size_t a : terms_on_line_[l])
      couplings.emplace_back(static_cast<Eigen::Index>(terms_[a].radius), coupling_[a]);
    // A centre's position t along the line couples with the line's centre (b) and its spheres'
    // radii (cₛ), and nothing else: t = (−g_t − bᵀ δ_line − Σ cₛ δ_radius) / a, substituted.
    for (const std::size_t c : centres_on_line_[l]) {
      const Eigen::Matrix3d& own = centre_block_[c];
      const double along = own(2, 2), gradient_along = centre_gradient_[c](2);
      const Eigen::Vector2d cross = own.block<2, 1>(0, 2);
      block += own.topLeftCorner<2, 2>() - cross * cross.transpose() / along;
      reduced_gradient_[l] += centre_gradient_[c].head<2>() - cross * (gradient_along / along);
      for (const std::size_t a : spheres_of_centre_[c]) {
        const double radius_along = sphere_coupling_[a](2);
        couplings.emplace_back(radius_of(a),
                               sphere_coupling_[a].head<2>() - cross * (radius_along / along));
        right(radius_of(a)) += radius_along * gradient_along / along;
        for (const std::size_t b : spheres_of_centre_[c])
          schur(radius_of(a), radius_of(b)) -= radius_along * sphere_coupling_[b](2) / along;
      }
    }
    inverse_[l] = block.inverse();
    for (const auto& [qa, ca] : couplings) {
      const Eigen::Vector2d spread = inverse_[l] * ca;
      right(qa) += spread.dot(reduced_gradient_[l]);
      for (const auto& [qb, cb] : couplings) schur(qa, qb) -= spread.dot(cb);
    }
  }
  for (std::size_t c = 0; c < centre_line_.size(); ++c) {
    if (centre_line_[c] != kNoLine) continue;
    centre_inverse_[c] = centre_block_[c].inverse();
    for (const std::size_t a : spheres_of_centre_[c]) {
      const Eigen::Vector3d spread = centre_inverse_[c] * sphere_coupling_[a];
      right(radius_of(a)) += spread.dot(centre_gradient_[c]);
      for (const std::size_t b : spheres_of_centre_[c])
        schur(radius_of(a), radius_of(b)) -= spread.dot(sphere_coupling_[b]);
    }
  }
  delta.tail(radius_count_) = solve_in_unit_scale(schur, right);
  for (std::size_t l = 0; l < line_block_.size(); ++l) {
    Eigen::Vector2d rest = -reduced_gradient_[l];
    for (const auto& [q, c] : reduced_coupling_[l]) rest -= c * delta(first_radius_ + q);
    delta.segment<2>(2 * static_cast<Eigen::Index>(l)) = inverse_[l] * rest;
  }
  for (std::size_t c = 0; c < centre_line_.size(); ++c) {
    if (centre_line_[c] == kNoLine) {
      Eigen::Vector3d rest = -centre_gradient_[c];
      for (const std::size_t s : spheres_of_centre_[c])
        rest -= sphere_coupling_[s] * delta(first_radius_ + radius_of(s));
      delta.segment<3>(centre_offset_[c]) = centre_inverse_[c] * rest;
      continue;
    }
    const Eigen::Vector2d line_step =
        delta.segment<2>(2 * static_cast<Eigen::Index>(centre_line_[c]));
    double rest = -centre_gradient_[c](2) - centre_block_[c].block<2, 1>(0, 2).dot(line_step);
    for (const std::size_t s : spheres_of_centre_[c])
      rest -= sphere_coupling_[s](2) * delta(first_radius_ + radius_of(s));
    delta(centre_offset_[c]) = rest / centre_block_[c](2, 2);
  }
  return delta;
}

std::optional<JointFit> JointSystem::result(double squares, bool with_covariance) const {
  const auto fitted_radii = x.tail(radius_count_);
  JointFit fit;
  for (Eigen::Index l = 0; l < lines_; ++l) fit.centres.emplace_back(x.segment<2>(2 * l));
  for (std::size_t c = 0; c < centre_line_.size(); ++c) {
    if (centre_line_[c] == kNoLine) {
      fit.sphere_centres.emplace_back(x.segment<3>(centre_offset_[c]));
      continue;
    }
    const Eigen::Vector3d& direction = directions_[centre_line_[c]];
    const auto [u, v] = orthonormal_pair(direction);
    const Eigen::Vector2d& centre = fit.centres[centre_line_[c]];
    fit.sphere_centres.emplace_back(centre.x() * u + centre.y() * v +
                                    x(centre_offset_[c]) * direction);
  }
  fit.radii.assign(fitted_radii.data(), fitted_radii.data() + fitted_radii.size());
  for (std::size_t k = 0; k < terms_.size() + spheres_.size(); ++k)
    fit.rms.push_back(std::max(
        std::sqrt(term_squares_[k] / double(std::max<std::size_t>(term_count_[k], 1))),
        kResolution *
            fit.radii[k < terms_.size() ? terms_[k].radius : spheres_[k - terms_.size()].radius]));
  if (with_covariance) {
    Eigen::MatrixXd normal;
    Eigen::VectorXd gradient;
    whole_system(normal, gradient);
    const double largest_radius = fitted_radii.maxCoeff();
    fit.covariance =
        normal.inverse() *
        std::max(squares / static_cast<double>(count - static_cast<std::size_t>(size_)),
                 kResolution * kResolution * largest_radius * largest_radius);
    if (!fit.covariance.allFinite()) return std::nullopt;
  }
  return fit;
}

}  // namespace

std::optional<JointFit> fit_cylinders_and_spheres(std::span<const Eigen::Vector3d> directions,
                                                  std::span<const Eigen::Vector2d> centres,
                                                  std::span<const Eigen::Vector3d> sphere_centres,
                                                  std::span<const double> radii,
                                                  std::span<const CylinderTerm> terms,
                                                  std::span<const SphereTerm> spheres,
                                                  bool with_covariance) {
  // Every centre has spheres, and they put it on one line or none.
  std::vector<std::optional<std::size_t>> centre_line(sphere_centres.size());
  for (const SphereTerm& sphere : spheres) {
    if (sphere.centre >= centre_line.size()) return std::nullopt;
    std::optional<std::size_t>& line = centre_line[sphere.centre];
    if (line && *line != sphere.line) return std::nullopt;
    line = sphere.line;
  }
  if (!std::all_of(centre_line.begin(), centre_line.end(),
                   [](const std::optional<std::size_t>& line) { return line.has_value(); }))
    return std::nullopt;
  JointSystem system(directions, centres, sphere_centres, radii, terms, spheres);
  for (int step = 0; step < 30; ++step) {
    system.linearise(true);
    const Eigen::VectorXd delta = system.step();
    if (!delta.allFinite()) return std::nullopt;
    system.x += delta;
    if (!(delta.norm() > 1e-14 * system.x.norm())) break;
  }
  const Eigen::Index parameters = system.x.size();
  if (!system.x.allFinite() ||
      !(system.x.tail(static_cast<Eigen::Index>(radii.size())).minCoeff() > 0))
    return std::nullopt;
  const double squares = system.linearise(false);
  if (system.count <= static_cast<std::size_t>(parameters)) return std::nullopt;
  return system.result(squares, with_covariance);
}

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

std::optional<CoaxialFit> fit_alone(const Primitive& cylinder, const Eigen::Vector3d& direction,
                                    std::span<const Vec3> points, std::span<const double> weights) {
  const auto [u, v] = orthonormal_pair(direction);
  const Eigen::Vector2d centre(u.dot(to_eigen(cylinder.point)), v.dot(to_eigen(cylinder.point)));
  const CoaxialMember alone{points, weights, cylinder.radius};
  return fit_coaxial(direction, centre, {&alone, 1});
}

std::optional<ConcentricFit> fit_concentric(const Eigen::Vector3d& centre,
                                            std::span<const CoaxialMember> members) {
  std::vector<SphereTerm> spheres;
  std::vector<double> radii;
  for (std::size_t j = 0; j < members.size(); ++j) {
    spheres.push_back({members[j].points, members[j].weights, j, kNoLine, 0});
    radii.push_back(members[j].radius);
  }
  const std::optional<JointFit> joint =
      fit_cylinders_and_spheres({}, {}, {&centre, 1}, radii, {}, spheres, true);
  if (!joint) return std::nullopt;
  ConcentricFit fit;
  fit.centre = joint->sphere_centres[0];
  fit.centre_covariance = joint->covariance.topLeftCorner<3, 3>();
  fit.radii = joint->radii;
  fit.rms = joint->rms;
  for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(members.size()); ++j)
    fit.radius_variances.push_back(joint->covariance(3 + j, 3 + j));
  return fit;
}

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

}  // namespace primseg::detail
