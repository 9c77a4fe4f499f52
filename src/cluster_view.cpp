// The union's quantities from the parts' centred moments. A part's points y_p about its own
// centroid are y = y_p + δ about the union's, with Σ w y_p = 0, so every moment of the union is the
// parts' moments expanded binomially in δ, and the terms with a first moment of y_p vanish:
//   Σ w y yᵀ        = S + w δ δᵀ
//   Σ w y |y|²      = t + 2 S δ + δ tr S + w δ |δ|²
//   Σ w |y|⁴        = f + 4 δ·t + 2 |δ|² tr S + 4 δᵀ S δ + w |δ|⁴
//   Σ w y (a·y)²    = v + 2 (a·δ) S a + δ aᵀSa + w δ (a·δ)²
//   Σ w |y|² (a·y)² = g + 2 (a·δ) a·t + (a·δ)² tr S + 2 δ·v + 4 (a·δ) δᵀ S a + |δ|² aᵀSa
//                       + w |δ|² (a·δ)²
//   Σ w (a·y)⁴      = h + 4 (a·δ) a·v + 6 (a·δ)² aᵀSa + w (a·δ)⁴
// with the part's S = Σ w y_p y_pᵀ, t = Σ w y_p |y_p|², f = Σ w |y_p|⁴, v = Σ w y_p (a·y_p)²,
// g = Σ w |y_p|² (a·y_p)², h = Σ w (a·y_p)⁴: contractions of its degree-3 and -4 moments.
// A single face given by its corners (FaceCorners) is summed directly instead, corner by corner,
// with y = (corner − its centroid) + δ: a few corners cost less than the 35 moments.
#include "primseg/cluster_view.hpp"

#include "symmetric_eigen3.hpp"
#include "union_placement.hpp"

namespace primseg {
namespace {

constexpr int at(int i, int j, int k) {
  return Moments::index(i, j, k);
}

Eigen::Matrix3d second_moment_of(const std::array<double, Moments::kCount>& m) {
  Eigen::Matrix3d s;
  s << m[at(2, 0, 0)], m[at(1, 1, 0)], m[at(1, 0, 1)],  //
      m[at(1, 1, 0)], m[at(0, 2, 0)], m[at(0, 1, 1)],   //
      m[at(1, 0, 1)], m[at(0, 1, 1)], m[at(0, 0, 2)];
  return s;
}

// Σ w y_p |y_p|² and Σ w |y_p|⁴ of one part.
ClusterView::RadialMoments radial_of(const std::array<double, Moments::kCount>& m) {
  ClusterView::RadialMoments r;
  r.third << m[at(3, 0, 0)] + m[at(1, 2, 0)] + m[at(1, 0, 2)],
      m[at(2, 1, 0)] + m[at(0, 3, 0)] + m[at(0, 1, 2)],
      m[at(2, 0, 1)] + m[at(0, 2, 1)] + m[at(0, 0, 3)];
  r.fourth = m[at(4, 0, 0)] + m[at(0, 4, 0)] + m[at(0, 0, 4)] +
             2 * (m[at(2, 2, 0)] + m[at(2, 0, 2)] + m[at(0, 2, 2)]);
  return r;
}

// Σ w y_p (a·y_p)², Σ w |y_p|² (a·y_p)², Σ w (a·y_p)⁴ of one part.
ClusterView::AxialMoments axial_of(const std::array<double, Moments::kCount>& m,
                                   const Eigen::Vector3d& a) {
  const double xx = a.x() * a.x(), yy = a.y() * a.y(), zz = a.z() * a.z();
  const double xy = 2 * a.x() * a.y(), xz = 2 * a.x() * a.z(), yz = 2 * a.y() * a.z();
  ClusterView::AxialMoments r;
  r.third.x() = m[at(3, 0, 0)] * xx + m[at(1, 2, 0)] * yy + m[at(1, 0, 2)] * zz +
                m[at(2, 1, 0)] * xy + m[at(2, 0, 1)] * xz + m[at(1, 1, 1)] * yz;
  r.third.y() = m[at(2, 1, 0)] * xx + m[at(0, 3, 0)] * yy + m[at(0, 1, 2)] * zz +
                m[at(1, 2, 0)] * xy + m[at(1, 1, 1)] * xz + m[at(0, 2, 1)] * yz;
  r.third.z() = m[at(2, 0, 1)] * xx + m[at(0, 2, 1)] * yy + m[at(0, 0, 3)] * zz +
                m[at(1, 1, 1)] * xy + m[at(1, 0, 2)] * xz + m[at(0, 1, 2)] * yz;
  // Σ_i M4(i, i, j, k) contracted with a_j a_k.
  r.mixed = (m[at(4, 0, 0)] + m[at(2, 2, 0)] + m[at(2, 0, 2)]) * xx +
            (m[at(2, 2, 0)] + m[at(0, 4, 0)] + m[at(0, 2, 2)]) * yy +
            (m[at(2, 0, 2)] + m[at(0, 2, 2)] + m[at(0, 0, 4)]) * zz +
            (m[at(3, 1, 0)] + m[at(1, 3, 0)] + m[at(1, 1, 2)]) * xy +
            (m[at(3, 0, 1)] + m[at(1, 2, 1)] + m[at(1, 0, 3)]) * xz +
            (m[at(2, 1, 1)] + m[at(0, 3, 1)] + m[at(0, 1, 3)]) * yz;
  // M4(a, a, a, a): each monomial times its multinomial coefficient 4! / (i! j! k!).
  r.fourth = m[at(4, 0, 0)] * xx * xx + m[at(0, 4, 0)] * yy * yy + m[at(0, 0, 4)] * zz * zz +
             6 * (m[at(2, 2, 0)] * xx * yy + m[at(2, 0, 2)] * xx * zz + m[at(0, 2, 2)] * yy * zz) +
             2 * (m[at(3, 1, 0)] * xx * xy + m[at(3, 0, 1)] * xx * xz + m[at(1, 3, 0)] * yy * xy +
                  m[at(0, 3, 1)] * yy * yz + m[at(1, 0, 3)] * zz * xz + m[at(0, 1, 3)] * zz * yz) +
             6 * (m[at(2, 1, 1)] * xx * yz + m[at(1, 2, 1)] * yy * xz + m[at(1, 1, 2)] * zz * xy);
  return r;
}

}  // namespace

ClusterView::ClusterView(const ClusterStats& centred)
    : parts_{centred, centred},
      part_count_(1),
      weight_(centred.moments.weight()),
      centroid_(centred.moments.origin()),
      second_moment_(second_moment_of(centred.moments.values())),
      triangle_count_(centred.triangle_count),
      area_(centred.area),
      normal_sum_(centred.normal_sum) {}

ClusterView::ClusterView(ClusterPart a, ClusterPart b, const EdgeStats& shared)
    : parts_{a, b},
      part_count_(2),
      shared_(&shared),
      weight_(a.weight() + b.weight()),
      triangle_count_(a.triangle_count() + b.triangle_count()),
      area_(a.area() + b.area()),
      normal_sum_(a.normal_sum() + b.normal_sum()) {
  const detail::UnionPlacement placement =
      detail::place_union(a.weight(), a.centroid(), b.weight(), b.centroid(), weight_);
  centroid_ = placement.centroid;
  shifts_[0] = placement.shift_a;
  shifts_[1] = placement.shift_b;
  second_moment_ = a.second_moment() + b.second_moment();
  second_moment_ += placement.second_moment_gain;
}

void ClusterView::compute_smallest_eigenpair() const {
  detail::Eigenpair e;
  eigen_steps_.count = detail::smallest_eigenpair(second_moment_, &e, &eigen_steps_.isolated,
                                                  &eigen_steps_.orthogonal);
  smallest_ = Eigenpair{e.value, e.vector};
}

const ClusterView::Eigensystem& ClusterView::second_moment_eigensystem() const {
  if (!eigensystem_) {
    // The plane's smallest pair has most often been asked for: its steps are most of the way.
    smallest_eigenpair();
    const detail::SymmetricEigen3 e = detail::symmetric_eigen3_from(
        second_moment_, eigen_steps_.count, eigen_steps_.isolated, eigen_steps_.orthogonal);
    eigensystem_ = Eigensystem{e.values, e.vectors};
  }
  return *eigensystem_;
}

Eigen::Matrix3d ClusterView::edge_tensor() const {
  if (part_count_ == 1) return parts_[0].edges().tensor_matrix();
  EdgeStats sum = parts_[0].edges();
  sum += parts_[1].edges();
  sum += *shared_;
  return sum.tensor_matrix();
}

const ClusterView::RadialMoments& ClusterView::radial_moments() const {
  if (radial_) return *radial_;
  radial_ = RadialMoments{Eigen::Vector3d::Zero(), 0.0};
  RadialMoments& sum = *radial_;
  for (int p = 0; p < part_count_; ++p) {
    const Eigen::Vector3d& d = shifts_[p];
    if (const FaceCorners* face = parts_[p].face()) {
      for (std::uint32_t k = 0; k < face->corner_count(); ++k) {
        const Eigen::Vector3d y = face->offsets[k] + d;
        const double w = face->weights[k], yy = y.squaredNorm();
        sum.third += (w * yy) * y;
        sum.fourth += w * yy * yy;
      }
      continue;
    }
    const Moments& m = parts_[p].stats()->moments;
    const RadialMoments part = radial_of(m.values());
    const Eigen::Matrix3d s = second_moment_of(m.values());
    const double w = m.weight(), trace = s.trace(), dd = d.squaredNorm();
    const Eigen::Vector3d sd = s * d;
    sum.third += part.third + 2 * sd + trace * d + (w * dd) * d;
    sum.fourth +=
        part.fourth + 4 * d.dot(part.third) + 2 * dd * trace + 4 * d.dot(sd) + w * dd * dd;
  }
  return sum;
}

ClusterView::AxialMoments ClusterView::axial_moments(const Eigen::Vector3d& axis) const {
  AxialMoments sum;
  for (int p = 0; p < part_count_; ++p) {
    const Eigen::Vector3d& d = shifts_[p];
    if (const FaceCorners* face = parts_[p].face()) {
      for (std::uint32_t k = 0; k < face->corner_count(); ++k) {
        const Eigen::Vector3d y = face->offsets[k] + d;
        const double w = face->weights[k], ay = axis.dot(y), way2 = w * ay * ay;
        sum.third += way2 * y;
        sum.mixed += way2 * y.squaredNorm();
        sum.fourth += way2 * ay * ay;
      }
      continue;
    }
    const Moments& m = parts_[p].stats()->moments;
    const AxialMoments part = axial_of(m.values(), axis);
    if (d.isZero(0)) {
      sum.third += part.third;
      sum.mixed += part.mixed;
      sum.fourth += part.fourth;
      continue;
    }
    const Eigen::Matrix3d s = second_moment_of(m.values());
    const Eigen::Vector3d radial_third = radial_of(m.values()).third;
    const double w = m.weight(), trace = s.trace(), dd = d.squaredNorm();
    const Eigen::Vector3d sa = s * axis;
    const double ad = axis.dot(d), asa = axis.dot(sa);
    sum.third += part.third + (2 * ad) * sa + asa * d + (w * ad * ad) * d;
    sum.mixed += part.mixed + 2 * ad * axis.dot(radial_third) + ad * ad * trace +
                 2 * d.dot(part.third) + 4 * ad * d.dot(sa) + dd * asa + w * dd * ad * ad;
    sum.fourth +=
        part.fourth + 4 * ad * axis.dot(part.third) + 6 * ad * ad * asa + w * ad * ad * ad * ad;
  }
  return sum;
}

double ClusterView::normal_alignment(const Eigen::Matrix3d& q, const Eigen::Vector3d& point,
                                     double radius) const {
  if (!(area_ > 0) || !(radius > 0)) return 0;
  // Σ A n · Q (c − p) over the triangles = tr(Q Σ (c − o)(A n)ᵀ) − (Σ A n)ᵀ Q (p − o), with each
  // part's Σ (c − o_p)(A n)ᵀ moved to the view's centroid by δ_p (Σ A n)ᵀ.
  if (!normal_position_) {
    Eigen::Matrix3d& sum = normal_position_.emplace(parts_[0].normal_position());
    sum.noalias() += shifts_[0] * parts_[0].normal_sum().transpose();
    for (int p = 1; p < part_count_; ++p) {
      sum += parts_[p].normal_position();
      sum.noalias() += shifts_[p] * parts_[p].normal_sum().transpose();
    }
  }
  // tr(Q N) = Σ_ij Q_ij N_ji.
  const double trace = q.cwiseProduct(normal_position_->transpose()).sum();
  const double sum = trace - normal_sum_.dot(q * (point - centroid_));
  return std::abs(sum) / (radius * area_);
}

std::array<const SampleReservoir*, 2> ClusterView::sample_strata() const {
  if (part_count_ == 2 && parts_[0].stats() && parts_[1].stats())
    return {&parts_[0].stats()->samples, &parts_[1].stats()->samples};
  return {&stats().samples, nullptr};
}

const ClusterStats& ClusterView::stats() const {
  if (part_count_ == 1) return *parts_[0].stats();
  if (!union_stats_) union_stats_ = stats(4);
  return *union_stats_;
}

ClusterStats ClusterView::stats(int max_degree) const {
  if (part_count_ == 1) return parts_[0].stats()->translated(centroid_, max_degree);
  ClusterStats result;
  if (const ClusterStats* first = parts_[0].stats()) {
    result = first->translated(centroid_, max_degree);
  } else {
    result.moments = Moments(centroid_);
    result.add(*parts_[0].face(), max_degree);
  }
  if (const ClusterStats* second = parts_[1].stats()) {
    result.merge(*second, *shared_, max_degree);
  } else {
    result.add(*parts_[1].face(), max_degree);
    result.edges += *shared_;
  }
  // About its centroid by construction: the first moments are round-off.
  result.moments.discard_first_moments();
  return result;
}

}  // namespace primseg
