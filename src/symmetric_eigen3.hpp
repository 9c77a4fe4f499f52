#pragma once
// Eigen-decomposition of a symmetric 3x3 matrix in closed form, for the merge loop's fits.
//
// Eigen's iterative solver (tridiagonalisation and implicit QR) takes about 235 ns for a 3x3
// matrix; its closed-form computeDirect() about 150 ns but its smallest eigenvalue can be off by
// 3e-13 of the trace, which is the whole cost of a nearly flat cluster. This one is as accurate as
// the iterative solver (eigenvalues within a few ulps of the matrix's norm) in a third of its
// time, with few divisions (the latency that dominates here):
//  1. the eigenvalue farthest from the middle one, by Halley's method on the characteristic cubic
//     (scaled and shifted by the mean eigenvalue): its gap to the others is at least half their
//     spread, so it is a simple root where the iteration converges fast;
//  2. its eigenvector, as the largest cross product of two rows of (A − λI);
//  3. the other two from the 2x2 problem in the plane orthogonal to it, which is well
//     conditioned however close those two eigenvalues are;
//  4. every eigenvalue recomputed as the Rayleigh quotient of its vector, which removes the
//     cubic's round-off (the error is quadratic in the vector's).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace primseg::detail {

/// Eigenvalues in ascending order and orthonormal eigenvectors (columns, same order).
struct SymmetricEigen3 {
  Eigen::Vector3d values;
  Eigen::Matrix3d vectors;
};

namespace eigen3_detail {

// A unit vector orthogonal to the unit vector v: v crossed with the axis it is least aligned
// with (|v × e| >= sqrt(2/3)).
inline Eigen::Vector3d any_orthogonal(const Eigen::Vector3d& v) {
  const double x = std::abs(v.x()), y = std::abs(v.y()), z = std::abs(v.z());
  Eigen::Vector3d u;
  if (x <= y && x <= z)
    u = {0, v.z(), -v.y()};  // v × e_x
  else if (y <= z)
    u = {-v.z(), 0, v.x()};  // v × e_y
  else
    u = {v.y(), -v.x(), 0};  // v × e_z
  return u * (1 / u.norm());
}

// Unit eigenvector of the symmetric b for its simple eigenvalue mu: the largest of the cross
// products of two rows of b − mu I (all three are parallel to it). Falls back to a vector
// orthogonal to a non-zero row when b − mu I has rank below 2 (mu is then not simple: any vector
// of its eigenspace will do).
inline Eigen::Vector3d eigenvector_of(const Eigen::Matrix3d& b, double mu) {
  const Eigen::Vector3d r0(b(0, 0) - mu, b(0, 1), b(0, 2));
  const Eigen::Vector3d r1(b(1, 0), b(1, 1) - mu, b(1, 2));
  const Eigen::Vector3d r2(b(2, 0), b(2, 1), b(2, 2) - mu);
  const Eigen::Vector3d c01 = r0.cross(r1), c02 = r0.cross(r2), c12 = r1.cross(r2);
  const double n01 = c01.squaredNorm(), n02 = c02.squaredNorm(), n12 = c12.squaredNorm();
  if (n01 >= n02 && n01 >= n12 && n01 > 0) return c01 * (1 / std::sqrt(n01));
  if (n02 >= n12 && n02 > 0) return c02 * (1 / std::sqrt(n02));
  if (n12 > 0) return c12 * (1 / std::sqrt(n12));
  for (const Eigen::Vector3d* r : {&r0, &r1, &r2})
    if (r->squaredNorm() > 0) return any_orthogonal(r->normalized());
  return Eigen::Vector3d::UnitX();
}

}  // namespace eigen3_detail

namespace eigen3_detail {

// The scaled, shifted matrix and its isolated eigenvalue (see the top of this file).
struct IsolatedRoot {
  enum Kind { kNotFinite, kZero, kScalar, kFound } kind = kFound;
  double scale = 0;   // max |a_ij|
  double mean = 0;    // mean eigenvalue of a / scale
  double p = 0;       // sqrt(Σ (λ − mean)² / 6) of a / scale
  Eigen::Matrix3d b;  // a / scale − mean I
  bool low = false;   // the isolated eigenvalue is the smallest, else the largest
  double x = 0;       // its root of 4x³ − 3x = r, positive: ±2p x is b's eigenvalue
  double shifted() const { return 2 * p * (low ? -x : x); }
};

// max |a_ij| of the symmetric a.
inline double max_entry(const Eigen::Matrix3d& a) {
  return std::max({std::abs(a(0, 0)), std::abs(a(1, 1)), std::abs(a(2, 2)), std::abs(a(0, 1)),
                   std::abs(a(0, 2)), std::abs(a(1, 2))});
}

// a / scale − mean I, with mean the mean eigenvalue of a / scale.
inline Eigen::Matrix3d scaled_and_shifted(const Eigen::Matrix3d& a, double scale, double* mean) {
  Eigen::Matrix3d b = a * (1 / scale);
  *mean = b.trace() / 3;
  b.diagonal().array() -= *mean;
  return b;
}

// (Forced inline, as the compiler chose while it had fewer callers: returned through memory from
// a call, the root cost bunny00's build 0.2% more instructions.)
inline __attribute__((always_inline)) IsolatedRoot isolated_root(const Eigen::Matrix3d& a) {
  IsolatedRoot root;
  root.scale = max_entry(a);
  // (std::max passes a NaN over: the sum of the entries does not.)
  if (!std::isfinite(root.scale + a(0, 0) + a(1, 1) + a(2, 2) + a(0, 1) + a(0, 2) + a(1, 2))) {
    root.kind = IsolatedRoot::kNotFinite;
    return root;
  }
  if (root.scale == 0) {
    root.kind = IsolatedRoot::kZero;
    return root;
  }
  Eigen::Matrix3d& b = root.b;
  b = scaled_and_shifted(a, root.scale, &root.mean);
  const double off = b(0, 1) * b(0, 1) + b(0, 2) * b(0, 2) + b(1, 2) * b(1, 2);
  const double p2 = (b(0, 0) * b(0, 0) + b(1, 1) * b(1, 1) + b(2, 2) * b(2, 2) + 2 * off) / 6;
  if (!(p2 > 0)) {
    root.kind = IsolatedRoot::kScalar;  // a multiple of the identity
    return root;
  }
  root.p = std::sqrt(p2);
  const double det = b(0, 0) * (b(1, 1) * b(2, 2) - b(1, 2) * b(1, 2)) -
                     b(0, 1) * (b(0, 1) * b(2, 2) - b(1, 2) * b(0, 2)) +
                     b(0, 2) * (b(0, 1) * b(1, 2) - b(1, 1) * b(0, 2));
  // The eigenvalues of b are 2p x for the three roots x of 4x³ − 3x = r (cos 3θ = r). For r >= 0
  // the largest root, in [√3/2, 1], is farthest from the middle one; for r < 0 the smallest,
  // by symmetry. Only that isolated root is needed: Halley's method from a quadratic fit of it
  // in 1 − |r| (exact at |r| = 1, within 1.1e-3 elsewhere) is within 1e-9 after one step and at
  // round-off after two.
  const double r = std::clamp(det / (2 * p2 * root.p), -1.0, 1.0);
  root.low = r < 0;
  const double abs_r = std::abs(r);
  const double t = 1 - abs_r;
  double x = 1 - t * (1.0 / 9 + 0.0229 * t);
  for (int step = 0; step < 2; ++step) {
    const double f = x * (4 * x * x - 3) - abs_r, slope = 12 * x * x - 3, curvature = 24 * x;
    x -= 2 * f * slope / (2 * slope * slope - f * curvature);
  }
  root.x = x;
  return root;
}

// The unit eigenvector of the smaller of the two eigenvalues of the symmetric b whose
// eigenvectors are orthogonal to the unit eigenvector `first`: from the 2x2 problem in the plane
// orthogonal to it, which is well conditioned however close those two eigenvalues are.
inline Eigen::Vector3d smaller_orthogonal_eigenvector(const Eigen::Matrix3d& b,
                                                      const Eigen::Vector3d& first) {
  // Basis (u, v) of the plane, matrix [[buu, buv], [buv, bvv]].
  Eigen::Vector3d u = eigen3_detail::any_orthogonal(first);  // (not const: returned)
  const Eigen::Vector3d v = first.cross(u);
  const Eigen::Vector3d bu = b * u, bv = b * v;
  const double buu = u.dot(bu), bvv = v.dot(bv), buv = u.dot(bv);
  // Eigenvector of the smaller eigenvalue μ = (buu + bvv)/2 − h: (buv, μ − buu) or
  // (μ − bvv, buv), the longer one (they are parallel); for a multiple of the identity, u.
  const double half_gap = 0.5 * (buu - bvv);
  const double h = std::sqrt(half_gap * half_gap + buv * buv);
  const double mu = 0.5 * (buu + bvv) - h;
  double cu = buv, cv = mu - buu;
  if (std::abs(mu - bvv) > std::abs(cv)) {
    cu = mu - bvv;
    cv = buv;
  }
  const double length2 = cu * cu + cv * cv;
  if (!(length2 > 0)) return u;
  return (cu * u + cv * v) * (1 / std::sqrt(length2));
}

// The full decomposition from the isolated eigenvalue's vector `first` and the smaller
// eigenvector orthogonal to it, `second`.
inline SymmetricEigen3 from_vectors(const Eigen::Matrix3d& a, const Eigen::Vector3d& first,
                                    const Eigen::Vector3d& second) {
  SymmetricEigen3 result;
  result.vectors.col(0) = first;
  result.vectors.col(1) = second;
  result.vectors.col(2) = first.cross(second);
  // Rayleigh quotients of the unscaled, unshifted matrix, then ascending order.
  for (int k = 0; k < 3; ++k)
    result.values(k) = result.vectors.col(k).dot(a * result.vectors.col(k));
  auto order = [&](int i, int j) {
    if (result.values(i) > result.values(j)) {
      std::swap(result.values(i), result.values(j));
      result.vectors.col(i).swap(result.vectors.col(j));
    }
  };
  order(0, 1);
  order(1, 2);
  order(0, 1);
  return result;
}

// The full decomposition from the isolated root.
inline SymmetricEigen3 complete(const Eigen::Matrix3d& a, const IsolatedRoot& root) {
  SymmetricEigen3 result;
  result.vectors = Eigen::Matrix3d::Identity();
  switch (root.kind) {
    case IsolatedRoot::kNotFinite:
      result.values = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
      return result;
    case IsolatedRoot::kZero:
      result.values = Eigen::Vector3d::Zero();  // every vector is an eigenvector
      return result;
    case IsolatedRoot::kScalar:
      result.values = Eigen::Vector3d::Constant(a(0, 0));
      return result;
    case IsolatedRoot::kFound:
      break;
  }
  const Eigen::Vector3d first = eigenvector_of(root.b, root.shifted());
  return from_vectors(a, first, smaller_orthogonal_eigenvector(root.b, first));
}

}  // namespace eigen3_detail

/// Eigen-decomposition of the symmetric matrix a. Input with a non-finite entry gives NaN
/// eigenvalues.
inline SymmetricEigen3 symmetric_eigen3(const Eigen::Matrix3d& a) {
  return eigen3_detail::complete(a, eigen3_detail::isolated_root(a));
}

/// One eigenvalue of a symmetric matrix and its unit eigenvector.
struct Eigenpair {
  double value = 0;
  Eigen::Vector3d vector = Eigen::Vector3d::UnitX();
};

/// smallest_eigenpair(a), also giving the vectors found on the way, from which
/// symmetric_eigen3_from() goes on: the isolated eigenvalue's unit vector and, when that eigenvalue
/// is the largest, the smaller one orthogonal to it. Returns how many it found: 0 for a zero,
/// scalar or non-finite matrix, else 1 or 2.
/// (Forced inline: the merge loop's plane fit calls it through ClusterView.)
inline __attribute__((always_inline)) int smallest_eigenpair(const Eigen::Matrix3d& a,
                                                             Eigenpair* smallest,
                                                             Eigen::Vector3d* isolated,
                                                             Eigen::Vector3d* orthogonal) {
  const eigen3_detail::IsolatedRoot root = eigen3_detail::isolated_root(a);
  if (root.kind != eigen3_detail::IsolatedRoot::kFound) {
    const SymmetricEigen3 all = eigen3_detail::complete(a, root);
    *smallest = {all.values(0), all.vectors.col(0)};
    return 0;
  }
  *isolated = eigen3_detail::eigenvector_of(root.b, root.shifted());
  if (root.low) {
    *smallest = {isolated->dot(a * *isolated), *isolated};
    return 1;
  }
  *orthogonal = eigen3_detail::smaller_orthogonal_eigenvector(root.b, *isolated);
  *smallest = {orthogonal->dot(a * *orthogonal), *orthogonal};
  return 2;
}

/// The smallest eigenvalue of the symmetric matrix a and its eigenvector: the first column of
/// symmetric_eigen3(a) (but where round-off would order two nearly equal eigenvalues the other
/// way), at about half its cost: the isolated eigenvalue's vector when it is the smallest, else
/// the smaller one of the 2x2 problem orthogonal to it.
inline Eigenpair smallest_eigenpair(const Eigen::Matrix3d& a) {
  Eigenpair smallest;
  Eigen::Vector3d isolated, orthogonal;
  smallest_eigenpair(a, &smallest, &isolated, &orthogonal);
  return smallest;
}

/// symmetric_eigen3(a), the same bits, from what smallest_eigenpair(a, ...) found: `count` (its
/// result) vectors, `orthogonal` read only when it is 2.
inline SymmetricEigen3 symmetric_eigen3_from(const Eigen::Matrix3d& a, int count,
                                             const Eigen::Vector3d& isolated,
                                             const Eigen::Vector3d& orthogonal) {
  if (count == 0) return symmetric_eigen3(a);
  if (count == 2) return eigen3_detail::from_vectors(a, isolated, orthogonal);
  // The shifted matrix as isolated_root() makes it (a few operations: the root was the costly
  // part).
  double mean = 0;
  const Eigen::Matrix3d b =
      eigen3_detail::scaled_and_shifted(a, eigen3_detail::max_entry(a), &mean);
  return eigen3_detail::from_vectors(a, isolated,
                                     eigen3_detail::smaller_orthogonal_eigenvector(b, isolated));
}

/// The eigenvalue of largest magnitude of the symmetric matrix a (the largest on a tie) and its
/// unit eigenvector, at about half the cost of symmetric_eigen3 when it is the isolated one.
inline Eigenpair dominant_eigenpair(const Eigen::Matrix3d& a) {
  const eigen3_detail::IsolatedRoot root = eigen3_detail::isolated_root(a);
  if (root.kind == eigen3_detail::IsolatedRoot::kFound) {
    // The other extreme root of 4x³ − 3x = |r|, opposite the isolated one, is
    // −(x + sqrt(3 (1 − x²))) / 2 in the isolated one's orientation.
    const double x = root.x;
    const double other = -(x + std::sqrt(std::max(0.0, 3 * (1 - x * x)))) / 2;
    const double isolated = root.mean + 2 * root.p * (root.low ? -x : x);
    const double opposite = root.mean + 2 * root.p * (root.low ? -other : other);
    if (std::abs(isolated) > std::abs(opposite)) {
      const Eigen::Vector3d v = eigen3_detail::eigenvector_of(root.b, root.shifted());
      return {v.dot(a * v), v};
    }
  }
  const SymmetricEigen3 all = eigen3_detail::complete(a, root);
  const int k = std::abs(all.values(0)) > std::abs(all.values(2)) ? 0 : 2;
  return {all.values(k), all.vectors.col(k)};
}

}  // namespace primseg::detail
