// Joint geometric fits of cylinders and spheres on shared axis lines and radii.
#include "regularity/stages.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstddef>
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
