#include "primseg/cluster_stats.hpp"

namespace primseg {
namespace {

struct Monomial {
  int i, j, k;
};

// Monomials ordered by degree, then lexicographically by decreasing exponent of x, y.
constexpr std::array<Monomial, Moments::kCount> make_monomials() {
  std::array<Monomial, Moments::kCount> table{};
  int n = 0;
  for (int degree = 0; degree <= 4; ++degree)
    for (int i = degree; i >= 0; --i)
      for (int j = degree - i; j >= 0; --j) table[n++] = {i, j, degree - i - j};
  return table;
}
constexpr auto kMonomials = make_monomials();

constexpr std::array<int, 125> make_index() {
  std::array<int, 125> index{};
  for (int n = 0; n < Moments::kCount; ++n)
    index[(kMonomials[n].i * 5 + kMonomials[n].j) * 5 + kMonomials[n].k] = n;
  return index;
}
constexpr auto kIndex = make_index();

constexpr double kBinomial[5][5] = {
    {1, 0, 0, 0, 0}, {1, 1, 0, 0, 0}, {1, 2, 1, 0, 0}, {1, 3, 3, 1, 0}, {1, 4, 6, 4, 1}};

// Exponents of the monomial of a full tensor entry (a, b, ...) with axis indices 0..2.
int index_of_axes(std::initializer_list<int> axes) {
  int e[3] = {0, 0, 0};
  for (int a : axes) ++e[a];
  return Moments::index(e[0], e[1], e[2]);
}

}  // namespace

int Moments::index(int i, int j, int k) {
  return kIndex[(i * 5 + j) * 5 + k];
}

Eigen::Vector3d Moments::centroid() const {
  if (!(values_[0] > 0)) return origin_;
  return origin_ + Eigen::Vector3d(values_[index(1, 0, 0)], values_[index(0, 1, 0)],
                                   values_[index(0, 0, 1)]) /
                       values_[0];
}

void Moments::add_point(const Eigen::Vector3d& x, double w) {
  const Eigen::Vector3d d = x - origin_;
  double px[5], py[5], pz[5];
  px[0] = py[0] = pz[0] = 1;
  for (int p = 1; p <= 4; ++p) {
    px[p] = px[p - 1] * d.x();
    py[p] = py[p - 1] * d.y();
    pz[p] = pz[p - 1] * d.z();
  }
  for (int n = 0; n < kCount; ++n) {
    const Monomial& m = kMonomials[n];
    values_[n] += w * (px[m.i] * py[m.j] * pz[m.k]);
  }
}

Moments Moments::translated(const Eigen::Vector3d& new_origin) const {
  // Σ w (y − d)^α with y = x − o and d = o' − o, expanded binomially per axis.
  const Eigen::Vector3d d = new_origin - origin_;
  double nx[5], ny[5], nz[5];
  nx[0] = ny[0] = nz[0] = 1;
  for (int p = 1; p <= 4; ++p) {
    nx[p] = nx[p - 1] * -d.x();
    ny[p] = ny[p - 1] * -d.y();
    nz[p] = nz[p - 1] * -d.z();
  }
  Moments result(new_origin);
  for (int n = 0; n < kCount; ++n) {
    const Monomial& m = kMonomials[n];
    double sum = 0;
    for (int a = 0; a <= m.i; ++a)
      for (int b = 0; b <= m.j; ++b)
        for (int c = 0; c <= m.k; ++c)
          sum += kBinomial[m.i][a] * kBinomial[m.j][b] * kBinomial[m.k][c] * nx[m.i - a] *
                 ny[m.j - b] * nz[m.k - c] * values_[kIndex[(a * 5 + b) * 5 + c]];
    result.values_[n] = sum;
  }
  return result;
}

Moments& Moments::operator+=(const Moments& other) {
  if (other.origin_ == origin_) {
    for (int n = 0; n < kCount; ++n) values_[n] += other.values_[n];
  } else {
    const Moments moved = other.translated(origin_);
    for (int n = 0; n < kCount; ++n) values_[n] += moved.values_[n];
  }
  return *this;
}

Eigen::Matrix3d Moments::second_moment() const {
  Eigen::Matrix3d s;
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b) s(a, b) = s(b, a) = values_[index_of_axes({a, b})];
  return s;
}

Eigen::Vector3d Moments::third_moment_contracted(const Eigen::Matrix3d& q) const {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c) v[a] += q(b, c) * values_[index_of_axes({a, b, c})];
  return v;
}

double Moments::fourth_moment_contracted(const Eigen::Matrix3d& q) const {
  double sum = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) sum += q(a, b) * q(c, d) * values_[index_of_axes({a, b, c, d})];
  return sum;
}

void ClusterStats::merge(const ClusterStats& other, const std::array<double, 6>& shared_tensor) {
  moments += other.moments;
  for (int n = 0; n < 6; ++n) tensor[n] += other.tensor[n] + shared_tensor[n];
  normal_sum += other.normal_sum;
  area += other.area;
  triangle_count += other.triangle_count;
}

Eigen::Matrix3d ClusterStats::tensor_matrix() const {
  Eigen::Matrix3d t;
  t << tensor[0], tensor[1], tensor[2], tensor[1], tensor[3], tensor[4], tensor[2], tensor[4],
      tensor[5];
  return t;
}

void add_edge_to_tensor(std::array<double, 6>& tensor, const Eigen::Vector3d& edge, double beta) {
  const double length = edge.norm();
  if (!(length > 0)) return;
  // |e| β ê êᵀ = (β / |e|) e eᵀ.
  const double s = beta / length;
  tensor[0] += s * edge.x() * edge.x();
  tensor[1] += s * edge.x() * edge.y();
  tensor[2] += s * edge.x() * edge.z();
  tensor[3] += s * edge.y() * edge.y();
  tensor[4] += s * edge.y() * edge.z();
  tensor[5] += s * edge.z() * edge.z();
}

}  // namespace primseg
