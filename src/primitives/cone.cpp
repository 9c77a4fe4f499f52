// Cone: apex from the face planes, then a Taubin fit of the cone at that apex.
//
// 1. Every tangent plane of a cone passes through its apex a, so a is the point nearest every
//    face plane: it minimises Σ A (n·(a − c))² (A area, n unit normal, c centroid of a face),
//    the 3×3 linear system (Σ A n nᵀ)(a − o) = Σ A n (n·(c − o)) of FacePlaneStats. A cylinder or
//    a plane has coplanar normals: the system is singular, the apex at infinity.
// 2. With y = x − a, a cone with apex a is a quadric yᵀ M y = 0, M symmetric (6 coefficients m).
//    Taubin's fit minimises Σ w (yᵀMy)² / Σ w |2My|² (both quadratic forms in m, from the moments
//    of degree 4 and 2 about the apex): a 6×6 generalised eigenproblem. The axis u is the
//    eigenvector of M's eigenvalue of distinct sign.
// 3. A circular cone is M = u uᵀ − cos²θ I: the same Taubin ratio over the span of u uᵀ and I
//    (a 2×2 generalised eigenproblem) gives cos²θ and the error of the reported cone.
// 4. Noise in the face normals biases the apex of step 1 (errors in variables: about σ_n² times
//    the cluster's distance to the apex over the normals' spread), and the axis and angle with
//    it. A few Levenberg–Marquardt steps on the same Taubin ratio over all six parameters
//    (refine_cone) follow, each kept only if it lowers the ratio; on exact data there is nothing
//    to lower.
// The error W × Σ w f² / Σ w |∇f|² (W = Σ w, f = yᵀMy) is the usual first-order estimate of
// Σ w d²: on the cone |∇f| = sin 2θ |y| grows with the distance to the apex, and dividing by its
// weighted mean square is unbiased when the deviations do not depend on that distance.
#include "primseg/primitives/cone.hpp"

#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>
#include <cstdint>

#include "small_cholesky.hpp"
#include "symmetric_eigen2.hpp"

namespace primseg {
namespace {

// Normals spanning less than this (smallest eigenvalue of Σ A n nᵀ over the area) leave the
// apex undetermined: flat or cylindrical data.
constexpr double kConeMinNormalSpread = 1e-9;
// Largest distance from the centroid to the apex, relative to the RMS spread of the points:
// beyond it the fit loses precision (moments of degree 4 about the apex) and the cluster is a
// cylinder or a plane for any practical purpose.
constexpr double kMaxRelativeApexDistance = 100;
// Σ w (u·y) over sqrt(W Σ w (u·y)²): 0.94 for a pointed cone sampled evenly by area, 1 for a
// narrow band; near 0 for points on both nappes, which the reported (one-sided) cone misses.
constexpr double kMinOneSidedness = 0.85;
// Levenberg–Marquardt steps of the joint refinement (each about a microsecond).
constexpr int kConeRefinementSteps = 6;

// The 6 coefficients m of a symmetric M in the order (xx, yy, zz, xy, xz, yz); yᵀMy = Σ m_k φ_k
// with φ = (x², y², z², 2xy, 2xz, 2yz).
using Coefficients = Eigen::Matrix<double, 6, 1>;
constexpr std::array<std::array<int, 3>, 6> kExponents = {
    {{2, 0, 0}, {0, 2, 0}, {0, 0, 2}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}}};
constexpr std::array<double, 6> kMultiplicity = {1, 1, 1, 2, 2, 2};
// (row, column) of M for each coefficient.
constexpr std::array<std::array<int, 2>, 6> kEntries = {
    {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}}};

// The eigenpairs of the quadric's 6×6 problem A x = λ B x (step 2; step 3's 2×2 one has a closed
// form in symmetric_eigen2.hpp), A symmetric and B symmetric positive definite: eigenvalues
// ascending, eigenvectors with xᵀBx = 1. The steps of Eigen's GeneralizedSelfAdjointEigenSolver
// (B = L Lᵀ, the ordinary problem of C = L⁻¹ A L⁻ᵀ, x = L⁻ᵀ y), with the written-out factor
// and substitutions of small_cholesky.hpp: Eigen's solver also compiles its two other problem types
// and its blocked matrix kernels, the slowest part of the slowest file to compile (g++ -O3: 65 s
// with it, 49 s without).
struct GeneralizedEigen {
  bool valid = false;
  Eigen::Matrix<double, 6, 1> values;
  Eigen::Matrix<double, 6, 6> vectors;  // one per column
};

GeneralizedEigen generalized_eigen(const Eigen::Matrix<double, 6, 6>& a,
                                   const Eigen::Matrix<double, 6, 6>& b) {
  using Matrix = Eigen::Matrix<double, 6, 6>;
  GeneralizedEigen result;
  Matrix l;
  if (!detail::cholesky_factor(b, l)) return result;
  // C = L⁻¹ (L⁻¹ A)ᵀ, A being symmetric.
  Matrix c = a;
  detail::solve_lower_in_place(l, c);
  c.transposeInPlace();
  detail::solve_lower_in_place(l, c);
  const Eigen::SelfAdjointEigenSolver<Matrix> ordinary(c);
  if (ordinary.info() != Eigen::Success) return result;
  result.values = ordinary.eigenvalues();
  result.vectors = ordinary.eigenvectors();
  detail::solve_lower_transposed_in_place(l, result.vectors);  // x = L⁻ᵀ y
  result.valid = true;
  return result;
}

Coefficients coefficients_of(const Eigen::Matrix3d& m) {
  Coefficients c;
  for (int k = 0; k < 6; ++k) c(k) = m(kEntries[k][0], kEntries[k][1]);
  return c;
}

Eigen::Matrix3d matrix_of(const Coefficients& c) {
  Eigen::Matrix3d m;
  for (int k = 0; k < 6; ++k)
    m(kEntries[k][0], kEntries[k][1]) = m(kEntries[k][1], kEntries[k][0]) = c(k);
  return m;
}

// Σ w φ φᵀ and Σ w (∇φ)ᵀ∇φ (so that mᵀ A m = Σ w f², mᵀ B m = Σ w |∇f|²) from moments about the
// apex, with lengths multiplied by `scale`.
struct TaubinSystem {
  Eigen::Matrix<double, 6, 6> a, b;
};

TaubinSystem taubin_system(const Moments& about_apex, double scale) {
  const double scale2 = scale * scale, scale4 = scale2 * scale2;
  TaubinSystem system;
  for (int k = 0; k < 6; ++k)
    for (int l = 0; l < 6; ++l)
      system.a(k, l) =
          kMultiplicity[k] * kMultiplicity[l] * scale4 *
          about_apex.at(kExponents[k][0] + kExponents[l][0], kExponents[k][1] + kExponents[l][1],
                        kExponents[k][2] + kExponents[l][2]);
  // ∇f = 2My; row r of My is yᵀ G_r m, with G_r selecting, for each coefficient, the coordinate
  // of y it multiplies in that row.
  const Eigen::Matrix3d s = about_apex.second_moment() * scale2;
  system.b.setZero();
  for (int r = 0; r < 3; ++r) {
    Eigen::Matrix<double, 3, 6> g = Eigen::Matrix<double, 3, 6>::Zero();
    for (int k = 0; k < 6; ++k) {
      const int row = kEntries[k][0], column = kEntries[k][1];
      if (row == r)
        g(column, k) = 1;
      else if (column == r)
        g(row, k) = 1;
    }
    system.b += 4 * g.transpose().lazyProduct(s.lazyProduct(g));
  }
  return system;
}

// The best circular cone with a given apex (steps 2 and 3), in the moments' frame.
struct ConeAtApex {
  bool valid = false;
  Moments about_apex;
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();  // either sign
  double cos2 = 0;                                 // cos² of the half-angle
  double ratio = 0;  // Σ w f² / Σ w |∇f|², in units of the RMS spread squared
};

ConeAtApex cone_at_apex(const Moments& moments, const Eigen::Vector3d& apex, double scale) {
  ConeAtApex cone;
  cone.about_apex = moments.translated(apex);
  const TaubinSystem system = taubin_system(cone.about_apex, scale);
  const GeneralizedEigen quadric = generalized_eigen(system.a, system.b);
  if (!quadric.valid) return cone;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> shape(matrix_of(quadric.vectors.col(0)));
  const Eigen::Vector3d& mu = shape.eigenvalues();  // ascending
  // The eigenvalue of distinct sign is the one farther from the middle one.
  const int distinct = mu(1) - mu(0) > mu(2) - mu(1) ? 0 : 2;
  cone.axis = shape.eigenvectors().col(distinct).normalized();

  // M = x₀ u uᵀ − x₁ I.
  Eigen::Matrix<double, 6, 2> span;
  span.col(0) = coefficients_of(cone.axis * cone.axis.transpose());
  span.col(1) = -coefficients_of(Eigen::Matrix3d::Identity());
  const Eigen::Matrix2d a2 = span.transpose().lazyProduct(system.a.lazyProduct(span));
  const Eigen::Matrix2d b2 = span.transpose().lazyProduct(system.b.lazyProduct(span));
  // In closed form: the ratio is the smaller eigenvalue, a few thousandths of the larger in a
  // typical fit and far less in a close one, which an iterative solver gets only to round-off of
  // the larger. Against a 60-digit reference on 100,924 matrices of the generated shapes' fits,
  // Eigen's solver erred by more than 3e-8 relatively on 1% of them, the closed form by 1.5e-15
  // at worst (session 59).
  const detail::SmallerGeneralizedEigenpair circular =
      detail::smaller_generalized_eigenpair(a2, b2);
  if (!circular.valid) return cone;
  const Eigen::Vector2d& x = circular.vector;
  cone.cos2 = x(1) / x(0);
  cone.ratio = std::max(0.0, circular.value);
  cone.valid = cone.cos2 > 0 && cone.cos2 < 1 && std::isfinite(cone.ratio);
  return cone;
}

// Polynomials of degree at most 2 in y, as coefficients of (1, x, y, z, x², y², z², xy, xz, yz):
// Σ w p q = pᵀ G q with G the 10×10 Gram matrix of moments up to degree 4. Every polynomial
// below is homogeneous (a constant, a linear form or a quadratic form), so only G's blocks
// between two degrees are multiplied: G₀₀ (1×1), G₀₁ (1×3), G₁₁ (3×3), G₁₂ (3×6), G₂₂ (6×6).
using Gram = Eigen::Matrix<double, 10, 10>;
using Quadratic = Eigen::Matrix<double, 6, 1>;  // coefficients of x², y², z², xy, xz, yz
// Where each entry of G comes from: the moment of the product of its two monomials, and that
// product's degree (the power of the length scale).
struct GramEntry {
  std::uint8_t moment;
  std::uint8_t degree;
};
constexpr std::array<std::array<GramEntry, 10>, 10> kGramEntries = [] {
  constexpr std::array<std::array<int, 3>, 10> monomials = {{{0, 0, 0},
                                                             {1, 0, 0},
                                                             {0, 1, 0},
                                                             {0, 0, 1},
                                                             {2, 0, 0},
                                                             {0, 2, 0},
                                                             {0, 0, 2},
                                                             {1, 1, 0},
                                                             {1, 0, 1},
                                                             {0, 1, 1}}};
  std::array<std::array<GramEntry, 10>, 10> entries{};
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const auto &a = monomials[i], &b = monomials[j];
      entries[i][j] = {
          static_cast<std::uint8_t>(Moments::index(a[0] + b[0], a[1] + b[1], a[2] + b[2])),
          static_cast<std::uint8_t>(a[0] + a[1] + a[2] + b[0] + b[1] + b[2])};
    }
  return entries;
}();

Gram gram_of(const Moments& moments, double scale) {
  double power[5] = {1, scale, scale * scale, 0, 0};
  power[3] = power[2] * scale;
  power[4] = power[2] * power[2];
  Gram g;
  for (int i = 0; i < 10; ++i)
    for (int j = i; j < 10; ++j) {
      const GramEntry entry = kGramEntries[i][j];
      g(i, j) = g(j, i) = moments.values()[entry.moment] * power[entry.degree];
    }
  return g;
}

auto linear_block(const Gram& g) {  // G₁₁
  return g.block<3, 3>(1, 1);
}
auto linear_quadratic_block(const Gram& g) {  // G₁₂
  return g.block<3, 6>(1, 4);
}
auto quadratic_block(const Gram& g) {  // G₂₂
  return g.block<6, 6>(4, 4);
}

Quadratic quadratic_form(const Eigen::Matrix3d& q) {  // yᵀ q y
  Quadratic p;
  p << q(0, 0), q(1, 1), q(2, 2), q(0, 1) + q(1, 0), q(0, 2) + q(2, 0), q(1, 2) + q(2, 1);
  return p;
}

struct ConeParameters {
  Eigen::Vector3d apex, axis;
  double cos2;
};

// N = Σ w f² and D = Σ w |∇f|² of f = yᵀ(u uᵀ − cos²θ I)y, lengths multiplied by `scale`.
std::pair<double, double> taubin_terms(const Gram& g, const ConeParameters& cone) {
  const Eigen::Matrix3d m =
      cone.axis * cone.axis.transpose() - cone.cos2 * Eigen::Matrix3d::Identity();
  const Quadratic f = quadratic_form(m);
  double d = 0;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d gradient = 2 * m.row(i).transpose();  // (∇f)_i = 2 (My)_i, linear
    d += gradient.dot(linear_block(g).lazyProduct(gradient));
  }
  return {f.dot(quadratic_block(g).lazyProduct(f)), d};
}

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

// Two unit vectors orthogonal to the unit axis u and to each other: the directions of its tilts.
struct TiltFrame {
  Eigen::Vector3d e1, e2;
};

TiltFrame tilt_frame(const Eigen::Vector3d& u) {
  Eigen::Index least;
  u.cwiseAbs().minCoeff(&least);
  const Eigen::Vector3d e1 = u.cross(Eigen::Vector3d::Unit(least)).normalized();
  return {e1, u.cross(e1)};
}

// N and D (taubin_terms()), and their gradients and Gauss–Newton Hessians over (apex, tilt e1,
// tilt e2, cos²θ).
struct TaubinDerivatives {
  Vector6 grad_n, grad_d;
  Matrix6 hess_n, hess_d;
  double n = 0, d = 0;
};

TaubinDerivatives taubin_derivatives(const Gram& g, const ConeParameters& cone,
                                     const TiltFrame& frame) {
  const Eigen::Vector3d& u = cone.axis;
  const Eigen::Vector3d &e1 = frame.e1, &e2 = frame.e2;
  const Eigen::Matrix3d m = u * u.transpose() - cone.cos2 * Eigen::Matrix3d::Identity();
  const Quadratic f = quadratic_form(m);
  // ∂f / ∂(apex, tilt e1, tilt e2, cos²θ): linear in y for the apex, quadratic for the rest.
  Eigen::Matrix3d by_apex;
  for (int k = 0; k < 3; ++k) by_apex.col(k) = -2 * m.row(k).transpose();
  Eigen::Matrix<double, 6, 3> by_shape;
  by_shape.col(0) = quadratic_form(u * e1.transpose() + e1 * u.transpose());
  by_shape.col(1) = quadratic_form(u * e2.transpose() + e2 * u.transpose());
  by_shape.col(2) = quadratic_form(-Eigen::Matrix3d::Identity());
  // Small fixed sizes: coefficient-wise products (lazyProduct) beat Eigen's blocked kernels.
  const auto g01 = g.block<1, 3>(0, 1);
  const auto g11 = linear_block(g);
  const auto g12 = linear_quadratic_block(g);
  const auto g22 = quadratic_block(g);
  const Quadratic g22f = g22.lazyProduct(f);
  TaubinDerivatives result;
  result.grad_n.head<3>() = 2 * by_apex.transpose().lazyProduct(g12.lazyProduct(f));
  result.grad_n.tail<3>() = 2 * by_shape.transpose().lazyProduct(g22f);
  Matrix6& hess_n = result.hess_n;
  hess_n.topLeftCorner<3, 3>() = 2 * by_apex.transpose().lazyProduct(g11.lazyProduct(by_apex));
  hess_n.topRightCorner<3, 3>() = 2 * by_apex.transpose().lazyProduct(g12.lazyProduct(by_shape));
  hess_n.bottomLeftCorner<3, 3>() = hess_n.topRightCorner<3, 3>().transpose();
  hess_n.bottomRightCorner<3, 3>() =
      2 * by_shape.transpose().lazyProduct(g22.lazyProduct(by_shape));
  // (∇f)_i = 2 (My)_i is linear in y; its derivatives are constant for the apex and linear for
  // the rest.
  Vector6& grad_d = result.grad_d;
  Matrix6& hess_d = result.hess_d;
  grad_d.setZero();
  hess_d.setZero();
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d gradient = 2 * m.row(i).transpose();
    const Eigen::RowVector3d constant = -2 * m.row(i);
    Eigen::Matrix3d linear;
    linear.col(0) = 2 * (u(i) * e1 + e1(i) * u);
    linear.col(1) = 2 * (u(i) * e2 + e2(i) * u);
    linear.col(2) = -2 * Eigen::Vector3d::Unit(i);
    const Eigen::Vector3d g_gradient = g11.lazyProduct(gradient);
    const double g01_gradient = g01.dot(gradient);
    grad_d.head<3>() += 2 * g01_gradient * constant.transpose();
    grad_d.tail<3>() += 2 * linear.transpose().lazyProduct(g_gradient);
    hess_d.topLeftCorner<3, 3>() += 2 * g(0, 0) * constant.transpose() * constant;
    const Eigen::Matrix3d mixed = 2 * constant.transpose() * (g01.lazyProduct(linear));
    hess_d.topRightCorner<3, 3>() += mixed;
    hess_d.bottomLeftCorner<3, 3>() += mixed.transpose();
    hess_d.bottomRightCorner<3, 3>() += 2 * linear.transpose().lazyProduct(g11.lazyProduct(linear));
    result.d += gradient.dot(g_gradient);
  }
  result.n = f.dot(g22f);
  return result;
}

// Where refine_cone() is: the cone, its ratio, the moments and Gram matrix about its apex, and
// Levenberg–Marquardt's damping.
struct ConeRefinement {
  ConeParameters& cone;
  double& ratio;
  Moments& about_apex;
  Gram g;
  double lambda = 1e-3;
};

// Damped steps along the Newton direction of N − R D, the damping raised tenfold after each that
// does not lower the ratio, until one does (then taken, and the damping lowered) or the damping
// reaches 1e8. Returns whether a step was taken and the ratio fell by more than 1e-12 of itself.
bool damped_step(const Moments& moments, double scale, const Vector6& gradient,
                 const Matrix6& hessian, const TiltFrame& frame, ConeRefinement& state) {
  while (state.lambda < 1e8) {
    Matrix6 damped = hessian;
    for (int k = 0; k < 6; ++k) damped(k, k) += state.lambda * std::abs(hessian(k, k)) + 1e-300;
    // Not positive definite away from a minimum: the step is then checked like any other.
    const Vector6 step = detail::solve_symmetric(damped, Vector6(-gradient));
    if (!step.allFinite()) {
      state.lambda *= 10;
      continue;
    }
    ConeParameters next = state.cone;
    next.apex += step.head<3>() / scale;
    next.axis = (state.cone.axis + step(3) * frame.e1 + step(4) * frame.e2).normalized();
    next.cos2 += step(5);
    if (!(next.cos2 > 0 && next.cos2 < 1)) {
      state.lambda *= 10;
      continue;
    }
    Moments moved = moments.translated(next.apex);
    const Gram next_gram = gram_of(moved, scale);
    const auto [n, next_d] = taubin_terms(next_gram, next);
    const double next_ratio = n / next_d;
    if (next_ratio < state.ratio) {
      const bool converged = state.ratio - next_ratio <= 1e-12 * state.ratio;
      state.cone = next;
      state.ratio = next_ratio;
      state.about_apex = std::move(moved);
      state.g = next_gram;
      state.lambda = std::max(state.lambda / 10, 1e-9);
      return !converged;
    }
    state.lambda *= 10;
  }
  return false;
}

// Levenberg–Marquardt on Taubin's ratio R = N / D over all six parameters at once (apex, axis
// tilt, cos²θ): a minimum of R is a stationary point of N − R D at fixed R. Every term is a
// polynomial of degree at most 2 in y, so the gradients and Gauss–Newton Hessians of N and D are
// Gram-matrix products of the moments about the current apex. Refining the apex alone, then the
// axis and angle, crawls along the valley where moving the apex along the axis trades with the
// angle; the joint step does not.
void refine_cone(const Moments& moments, double scale, ConeParameters& cone, double& ratio,
                 Moments& about_apex) {
  ConeRefinement state{cone, ratio, about_apex, gram_of(about_apex, scale)};
  for (int iteration = 0; iteration < kConeRefinementSteps; ++iteration) {
    const TiltFrame frame = tilt_frame(cone.axis);
    const TaubinDerivatives derivatives = taubin_derivatives(state.g, cone, frame);
    if (!(derivatives.d > 0)) return;
    const double r = derivatives.n / derivatives.d;
    const Vector6 gradient = derivatives.grad_n - r * derivatives.grad_d;
    const Matrix6 hessian = derivatives.hess_n - r * derivatives.hess_d;
    if (!damped_step(moments, scale, gradient, hessian, frame, state)) return;
  }
}

}  // namespace

std::uint32_t ConeFitter::min_triangles() const {
  return 6;
}

PrimitiveFit ConeFitter::fit(const ClusterView& cluster, double /*error_to_beat*/) const {
  const ClusterStats& centred = cluster.stats();
  PrimitiveFit result;
  result.primitive.type = PrimitiveType::Cone;
  const Moments& m = centred.moments;
  const double weight = m.weight();
  if (centred.triangle_count < min_triangles() || !(centred.area > 0) || !(weight > 0))
    return result;
  const double spread2 = m.second_moment().trace() / weight;
  if (!(spread2 > 0) || !std::isfinite(spread2)) return result;
  const double scale = 1 / std::sqrt(spread2);

  // 1. The apex.
  const Eigen::Matrix3d normals = centred.face_planes.normal_normal_matrix();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> normal_eigen(normals);
  if (!(normal_eigen.eigenvalues()(0) > kConeMinNormalSpread * centred.area)) return result;
  const Eigen::Vector3d apex_offset =
      normal_eigen.eigenvectors() *
      ((normal_eigen.eigenvectors().transpose() * centred.face_planes.normal_offset)
           .cwiseQuotient(normal_eigen.eigenvalues()));
  if (!(apex_offset.norm() * scale <= kMaxRelativeApexDistance)) return result;
  // 2, 3. The cone at that apex; 4. all its parameters refined together.
  ConeAtApex start = cone_at_apex(m, m.origin() + apex_offset, scale);
  if (!start.valid) return result;
  ConeParameters cone{m.origin() + apex_offset, start.axis, start.cos2};
  double ratio = start.ratio;
  Moments about_apex = std::move(start.about_apex);
  refine_cone(m, scale, cone, ratio, about_apex);
  if (!((cone.apex - m.origin()).norm() * scale <= kMaxRelativeApexDistance)) return result;
  const Eigen::Vector3d apex = cone.apex;
  Eigen::Vector3d axis = cone.axis;
  const double cos2 = cone.cos2;
  const double half_angle = std::acos(std::sqrt(cos2));
  if (!(half_angle >= kMinConeHalfAngle && half_angle <= M_PI / 2 - kMinConeHalfAngle))
    return result;
  // One nappe, the axis pointing into it.
  const Eigen::Vector3d mean_offset = (m.origin() - apex);  // centroid − apex
  if (axis.dot(mean_offset) < 0) axis = -axis;
  const double along_sum = weight * axis.dot(mean_offset);
  const double along_square = axis.dot(about_apex.second_moment() * axis);
  if (!(along_sum > kMinOneSidedness * std::sqrt(weight * along_square))) return result;

  // Face normals must follow the cone's: n·(u uᵀ − cos²θ I)(c − a) = ± cos θ sin θ |c − a|.
  const double cos_angle = std::cos(half_angle), sin_angle = std::sin(half_angle);
  const double rms_distance = std::sqrt(about_apex.second_moment().trace() / weight);
  const Eigen::Matrix3d q = axis * axis.transpose() - cos2 * Eigen::Matrix3d::Identity();
  result.normal_alignment = centred.normal_alignment(q, apex, cos_angle * sin_angle * rms_distance);
  if (result.normal_alignment < kMinNormalAlignment) return result;

  result.valid = true;
  result.error = weight * ratio * spread2;
  result.primitive.point = {apex.x(), apex.y(), apex.z()};
  result.primitive.axis = {axis.x(), axis.y(), axis.z()};
  result.primitive.half_angle = half_angle;
  return result;
}

}  // namespace primseg
