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

// The normal equations of fit_cylinders_and_spheres() at x = (line centres 2 each, free sphere
// centres 3 each, positions of the spheres on a line along it, radii), by blocks: each line's
// own 2x2, each term's coupling of its line and its radius, each radius's diagonal (radii never
// couple with each other, lines never with lines). A sphere's 3x3 block is over its centre, or
// over its line's centre and its position along it.
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
  // The radii's Schur complement S = D − Σ Bₗᵀ Aₗ⁻¹ Bₗ, then each line's and sphere's position.
  Eigen::VectorXd step_by_blocks();

  std::span<const Eigen::Vector3d> directions_;
  std::span<const CylinderTerm> terms_;
  std::span<const SphereTerm> spheres_;
  Eigen::Index lines_, radius_count_, first_radius_, size_;
  std::vector<Eigen::Index> sphere_offset_;
  // The points in the plane orthogonal to their line's direction, once for every iteration; a
  // sphere's on a line in its frame (u, v, direction).
  std::vector<std::vector<Eigen::Vector2d>> projected_;
  std::vector<std::vector<Eigen::Vector3d>> sphere_local_;
  std::vector<std::vector<std::size_t>> terms_on_line_, spheres_on_line_;
  std::vector<Eigen::Matrix2d> line_block_;
  std::vector<Eigen::Vector2d> coupling_, line_gradient_;
  std::vector<Eigen::Matrix3d> sphere_block_;
  std::vector<Eigen::Vector3d> sphere_coupling_, sphere_gradient_;
  Eigen::VectorXd radius_diagonal_, radius_gradient_;
  // Per cylinder term, then per sphere.
  std::vector<double> term_squares_;
  std::vector<std::size_t> term_count_;
  // step_by_blocks()'s: per line, with the positions of its spheres along it eliminated, its
  // block's inverse, its gradient, and the coupling of each of its terms (cylinders, then
  // spheres) with that term's radius; per free sphere, its block's inverse.
  std::vector<Eigen::Matrix2d> inverse_;
  std::vector<Eigen::Vector2d> reduced_gradient_;
  std::vector<std::vector<std::pair<Eigen::Index, Eigen::Vector2d>>> reduced_coupling_;
  std::vector<Eigen::Matrix3d> sphere_inverse_;
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
      sphere_offset_(spheres.size()),
      projected_(terms.size()),
      sphere_local_(spheres.size()),
      terms_on_line_(centres.size()),
      spheres_on_line_(centres.size()),
      line_block_(centres.size()),
      coupling_(terms.size()),
      line_gradient_(centres.size()),
      sphere_block_(spheres.size()),
      sphere_coupling_(spheres.size()),
      sphere_gradient_(spheres.size()),
      radius_diagonal_(radius_count_),
      radius_gradient_(radius_count_),
      term_squares_(terms.size() + spheres.size()),
      term_count_(terms.size() + spheres.size()),
      inverse_(centres.size()),
      reduced_gradient_(centres.size()),
      reduced_coupling_(centres.size()),
      sphere_inverse_(spheres.size()) {
  const Eigen::Index free_spheres = std::count_if(
      spheres.begin(), spheres.end(), [](const SphereTerm& s) { return s.line == kNoLine; });
  Eigen::Index next_free = 2 * lines_, next_on_line = 2 * lines_ + 3 * free_spheres;
  for (std::size_t s = 0; s < spheres.size(); ++s)
    sphere_offset_[s] =
        spheres[s].line == kNoLine ? std::exchange(next_free, next_free + 3) : next_on_line++;
  first_radius_ = next_on_line;
  size_ = first_radius_ + radius_count_;
  x.resize(size_);
  for (Eigen::Index l = 0; l < lines_; ++l) x.segment<2>(2 * l) = centres[l];
  for (std::size_t s = 0; s < spheres.size(); ++s) {
    if (spheres[s].line == kNoLine)
      x.segment<3>(sphere_offset_[s]) = sphere_centres[s];
    else
      x(sphere_offset_[s]) = directions[spheres[s].line].dot(sphere_centres[s]);
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
    spheres_on_line_[l].push_back(s);
  }
}

double JointSystem::linearise(bool weighted) {
  std::fill(line_block_.begin(), line_block_.end(), Eigen::Matrix2d::Zero());
  std::fill(coupling_.begin(), coupling_.end(), Eigen::Vector2d::Zero());
  std::fill(line_gradient_.begin(), line_gradient_.end(), Eigen::Vector2d::Zero());
  std::fill(sphere_block_.begin(), sphere_block_.end(), Eigen::Matrix3d::Zero());
  std::fill(sphere_coupling_.begin(), sphere_coupling_.end(), Eigen::Vector3d::Zero());
  std::fill(sphere_gradient_.begin(), sphere_gradient_.end(), Eigen::Vector3d::Zero());
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
    const Eigen::Index offset = sphere_offset_[s];
    const double radius = x(first_radius_ + q);
    const std::size_t k = terms_.size() + s;
    term_squares_[k] = 0;
    term_count_[k] = 0;
    if (spheres_[s].line == kNoLine) {
      const Eigen::Vector3d centre = x.segment<3>(offset);
      for (std::size_t i = 0; i < spheres_[s].points.size(); ++i)
        add_point((to_eigen(spheres_[s].points[i]) - centre).eval(), radius,
                  weighted ? spheres_[s].weights[i] : 1.0, sphere_block_[s], sphere_coupling_[s],
                  sphere_gradient_[s], q, k);
    } else {
      const Eigen::Index l = 2 * static_cast<Eigen::Index>(spheres_[s].line);
      const Eigen::Vector3d centre(x(l), x(l + 1), x(offset));
      for (std::size_t i = 0; i < sphere_local_[s].size(); ++i)
        add_point((sphere_local_[s][i] - centre).eval(), radius,
                  weighted ? spheres_[s].weights[i] : 1.0, sphere_block_[s], sphere_coupling_[s],
                  sphere_gradient_[s], q, k);
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
  for (std::size_t s = 0; s < spheres_.size(); ++s) {
    const Eigen::Index o = sphere_offset_[s];
    const Eigen::Index q = first_radius_ + static_cast<Eigen::Index>(spheres_[s].radius);
    if (spheres_[s].line == kNoLine) {
      normal.block<3, 3>(o, o) = sphere_block_[s];
      gradient.segment<3>(o) = sphere_gradient_[s];
      normal.block<3, 1>(o, q) += sphere_coupling_[s];
      continue;
    }
    const Eigen::Index l = 2 * static_cast<Eigen::Index>(spheres_[s].line);
    normal.block<2, 2>(l, l) += sphere_block_[s].topLeftCorner<2, 2>();
    normal.block<2, 1>(l, o) = sphere_block_[s].block<2, 1>(0, 2);
    normal.block<1, 2>(o, l) = sphere_block_[s].block<1, 2>(2, 0);
    normal(o, o) = sphere_block_[s](2, 2);
    gradient.segment<2>(l) += sphere_gradient_[s].head<2>();
    gradient(o) = sphere_gradient_[s](2);
    normal.block<2, 1>(l, q) += sphere_coupling_[s].head<2>();
    normal(o, q) += sphere_coupling_[s](2);
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
    return normal.ldlt().solve(-gradient);
  }
  return step_by_blocks();
}

Eigen::VectorXd JointSystem::step_by_blocks() {
  Eigen::VectorXd delta(size_);
  Eigen::MatrixXd schur = radius_diagonal_.asDiagonal();
  Eigen::VectorXd right = -radius_gradient_;
  for (std::size_t l = 0; l < line_block_.size(); ++l) {
    Eigen::Matrix2d block = line_block_[l];
    reduced_gradient_[l] = line_gradient_[l];
    std::vector<std::pair<Eigen::Index, Eigen::Vector2d>>& couplings = reduced_coupling_[l];
    couplings.clear();
    for (const std::size_t a : terms_on_line_[l])
      couplings.emplace_back(static_cast<Eigen::Index>(terms_[a].radius), coupling_[a]);
    // A sphere's position t along the line couples with the line's centre (b), its radius (c)
    // and nothing else: t = (−g_t − bᵀ δ_line − c δ_radius) / a, substituted.
    for (const std::size_t s : spheres_on_line_[l]) {
      const Eigen::Matrix3d& own = sphere_block_[s];
      const double along = own(2, 2), radius_along = sphere_coupling_[s](2),
                   gradient_along = sphere_gradient_[s](2);
      const Eigen::Vector2d cross = own.block<2, 1>(0, 2);
      const Eigen::Index q = static_cast<Eigen::Index>(spheres_[s].radius);
      block += own.topLeftCorner<2, 2>() - cross * cross.transpose() / along;
      reduced_gradient_[l] += sphere_gradient_[s].head<2>() - cross * (gradient_along / along);
      couplings.emplace_back(q, sphere_coupling_[s].head<2>() - cross * (radius_along / along));
      schur(q, q) -= radius_along * radius_along / along;
      right(q) += radius_along * gradient_along / along;
    }
    inverse_[l] = block.inverse();
    for (const auto& [qa, ca] : couplings) {
      const Eigen::Vector2d spread = inverse_[l] * ca;
      right(qa) += spread.dot(reduced_gradient_[l]);
      for (const auto& [qb, cb] : couplings) schur(qa, qb) -= spread.dot(cb);
    }
  }
  for (std::size_t s = 0; s < spheres_.size(); ++s) {
    if (spheres_[s].line != kNoLine) continue;
    sphere_inverse_[s] = sphere_block_[s].inverse();
    const Eigen::Vector3d spread = sphere_inverse_[s] * sphere_coupling_[s];
    const Eigen::Index q = static_cast<Eigen::Index>(spheres_[s].radius);
    right(q) += spread.dot(sphere_gradient_[s]);
    schur(q, q) -= spread.dot(sphere_coupling_[s]);
  }
  delta.tail(radius_count_) = schur.ldlt().solve(right);
  for (std::size_t l = 0; l < line_block_.size(); ++l) {
    Eigen::Vector2d rest = -reduced_gradient_[l];
    for (const auto& [q, c] : reduced_coupling_[l]) rest -= c * delta(first_radius_ + q);
    delta.segment<2>(2 * static_cast<Eigen::Index>(l)) = inverse_[l] * rest;
  }
  for (std::size_t s = 0; s < spheres_.size(); ++s) {
    const double radius_step = delta(first_radius_ + static_cast<Eigen::Index>(spheres_[s].radius));
    if (spheres_[s].line == kNoLine) {
      const Eigen::Vector3d rest = -sphere_gradient_[s] - sphere_coupling_[s] * radius_step;
      delta.segment<3>(sphere_offset_[s]) = sphere_inverse_[s] * rest;
    } else {
      const Eigen::Vector2d line_step =
          delta.segment<2>(2 * static_cast<Eigen::Index>(spheres_[s].line));
      delta(sphere_offset_[s]) =
          (-sphere_gradient_[s](2) - sphere_block_[s].block<2, 1>(0, 2).dot(line_step) -
           sphere_coupling_[s](2) * radius_step) /
          sphere_block_[s](2, 2);
    }
  }
  return delta;
}

std::optional<JointFit> JointSystem::result(double squares, bool with_covariance) const {
  const auto fitted_radii = x.tail(radius_count_);
  JointFit fit;
  for (Eigen::Index l = 0; l < lines_; ++l) fit.centres.emplace_back(x.segment<2>(2 * l));
  for (std::size_t s = 0; s < spheres_.size(); ++s) {
    if (spheres_[s].line == kNoLine) {
      fit.sphere_centres.emplace_back(x.segment<3>(sphere_offset_[s]));
      continue;
    }
    const Eigen::Vector3d& direction = directions_[spheres_[s].line];
    const auto [u, v] = orthonormal_pair(direction);
    const Eigen::Vector2d& centre = fit.centres[spheres_[s].line];
    fit.sphere_centres.emplace_back(centre.x() * u + centre.y() * v +
                                    x(sphere_offset_[s]) * direction);
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
                                            std::span<const CoaxialMember> members,
                                            std::span<const std::size_t> radius_of) {
  const auto radius_index = [&](std::size_t j) {
    return 3 + static_cast<Eigen::Index>(radius_of.empty() ? j : radius_of[j]);
  };
  Eigen::Index size = 3;
  for (std::size_t j = 0; j < members.size(); ++j) size = std::max(size, radius_index(j) + 1);
  std::size_t count = 0;
  for (const CoaxialMember& member : members) count += member.points.size();
  if (count <= static_cast<std::size_t>(size)) return std::nullopt;
  Eigen::VectorXd x = Eigen::VectorXd::Constant(size, std::numeric_limits<double>::quiet_NaN());
  x.head<3>() = centre;
  for (std::size_t j = members.size(); j-- > 0;) x(radius_index(j)) = members[j].radius;
  if (!x.allFinite()) return std::nullopt;  // a radius no member has
  Eigen::MatrixXd normal(size, size);
  Eigen::VectorXd gradient(size);
  std::vector<double> member_squares(members.size());
  // The normal equations at x, each residual |p − c| − rⱼ weighted or not; the unweighted Σ e².
  const auto linearise = [&](bool weighted) {
    normal.setZero();
    gradient.setZero();
    double squares = 0;
    for (std::size_t j = 0; j < members.size(); ++j) {
      const Eigen::Index q = radius_index(j);
      member_squares[j] = 0;
      for (std::size_t i = 0; i < members[j].points.size(); ++i) {
        const Eigen::Vector3d d = to_eigen(members[j].points[i]) - x.head<3>();
        const double length = d.norm();
        if (!(length > 0)) continue;
        const double e = length - x(q), w = weighted ? members[j].weights[i] : 1.0;
        const Eigen::Vector3d by_centre = -d / length;
        normal.topLeftCorner<3, 3>() += w * by_centre * by_centre.transpose();
        normal.block<3, 1>(0, q) -= w * by_centre;
        normal(q, q) += w;
        gradient.head<3>() += w * e * by_centre;
        gradient(q) -= w * e;
        squares += e * e;
        member_squares[j] += e * e;
      }
    }
    normal.bottomLeftCorner(size - 3, 3) = normal.topRightCorner(3, size - 3).transpose();
    return squares;
  };
  bool converged = false;
  for (int step = 0; step < 30 && !converged; ++step) {
    linearise(true);
    const Eigen::VectorXd delta = normal.ldlt().solve(-gradient);
    if (!delta.allFinite()) return std::nullopt;
    x += delta;
    converged = !(delta.norm() > 1e-14 * x.norm());
  }
  if (!converged || !x.allFinite() || !(x.tail(size - 3).minCoeff() > 0)) return std::nullopt;
  const double squares = linearise(false);
  const double largest_radius = x.tail(size - 3).maxCoeff();
  const Eigen::MatrixXd covariance =
      normal.inverse() *
      std::max(squares / static_cast<double>(count - static_cast<std::size_t>(size)),
               kResolution * kResolution * largest_radius * largest_radius);
  if (!covariance.allFinite()) return std::nullopt;
  ConcentricFit fit;
  fit.centre = x.head<3>();
  fit.centre_covariance = covariance.topLeftCorner<3, 3>();
  for (std::size_t j = 0; j < members.size(); ++j) {
    const Eigen::Index q = radius_index(j);
    fit.radii.push_back(x(q));
    fit.radius_variances.push_back(covariance(q, q));
    fit.rms.push_back(std::max(
        std::sqrt(member_squares[j] / double(std::max<std::size_t>(members[j].points.size(), 1))),
        kResolution * x(q)));
  }
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
