#include "primseg/cluster_stats.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "union_placement.hpp"

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

// One term C(α, β) (−d)^(α−β) M_β of the translation of monomial α.
struct TranslationTerm {
  std::uint8_t target, source, shift;
  double coefficient;
};

constexpr int count_translation_terms() {
  int n = 0;
  for (const Monomial& m : kMonomials) n += (m.i + 1) * (m.j + 1) * (m.k + 1);
  return n;
}

constexpr auto make_translation_terms() {
  std::array<TranslationTerm, count_translation_terms()> terms{};
  int n = 0;
  for (int target = 0; target < Moments::kCount; ++target) {
    const Monomial& m = kMonomials[target];
    for (int a = 0; a <= m.i; ++a)
      for (int b = 0; b <= m.j; ++b)
        for (int c = 0; c <= m.k; ++c)
          terms[n++] = {
              static_cast<std::uint8_t>(target),
              static_cast<std::uint8_t>(kIndex[(a * 5 + b) * 5 + c]),
              static_cast<std::uint8_t>(kIndex[((m.i - a) * 5 + (m.j - b)) * 5 + (m.k - c)]),
              kBinomial[m.i][a] * kBinomial[m.j][b] * kBinomial[m.k][c]};
  }
  return terms;
}
constexpr auto kTranslationTerms = make_translation_terms();

constexpr std::size_t count_terms_up_to_degree2() {
  std::size_t n = 0;
  while (n < kTranslationTerms.size() && kTranslationTerms[n].target < Moments::kCountUpToDegree2)
    ++n;
  return n;
}
constexpr std::size_t kTermsUpToDegree2 = count_terms_up_to_degree2();
static_assert(kTermsUpToDegree2 == 28);

// The terms whose source is not a first moment: all that is needed for moments about their own
// centroid (first moments zero), about two thirds of them. Same order.
constexpr bool is_first_moment(int index) {
  return index >= 1 && index <= 3;
}
constexpr std::size_t count_centred_terms(std::size_t end) {
  std::size_t n = 0;
  for (std::size_t t = 0; t < end; ++t) n += !is_first_moment(kTranslationTerms[t].source);
  return n;
}
template <std::size_t count>
constexpr std::array<TranslationTerm, count> make_centred_terms() {
  std::array<TranslationTerm, count> terms{};
  std::size_t n = 0;
  for (const TranslationTerm& term : kTranslationTerms)
    if (!is_first_moment(term.source) && n < count) terms[n++] = term;
  return terms;
}
constexpr auto kCentredTerms = make_centred_terms<count_centred_terms(kTranslationTerms.size())>();
constexpr std::size_t kCentredTermsUpToDegree2 = count_centred_terms(kTermsUpToDegree2);

template <const auto& terms, std::size_t... n>
inline void apply_translation_terms(std::index_sequence<n...>, const double* shift,
                                    const double* source, double* target) {
  ((target[terms[n].target] +=
    terms[n].coefficient * shift[terms[n].shift] * source[terms[n].source]),
   ...);
}

// values[n] += w x^i y^j z^k for every monomial n, unrolled at compile time.
template <std::size_t... n>
inline void add_monomials(std::index_sequence<n...>, const double* px, const double* py,
                          const double* pz, double w, double* values) {
  ((values[n] += w * (px[kMonomials[n].i] * py[kMonomials[n].j] * pz[kMonomials[n].k])), ...);
}

// Monomial index of the full tensor entry with axes (a, b, c, d) (a 4-digit base-3 number;
// lower degrees pad with the axis value 3, which adds no exponent).
constexpr std::array<std::uint8_t, 256> make_axes_index() {
  std::array<std::uint8_t, 256> table{};
  for (int key = 0; key < 256; ++key) {
    int e[4] = {0, 0, 0, 0};
    for (int digit = 0, k = key; digit < 4; ++digit, k /= 4) ++e[k % 4];
    if (e[0] + e[1] + e[2] + e[3] == 4)
      table[key] = static_cast<std::uint8_t>(kIndex[(e[0] * 5 + e[1]) * 5 + e[2]]);
  }
  return table;
}
constexpr auto kAxesIndex = make_axes_index();

constexpr int axes(int a, int b, int c = 3, int d = 3) {
  return kAxesIndex[a + 4 * (b + 4 * (c + 4 * d))];
}

}  // namespace

static_assert([] {
  for (int n = 0; n < Moments::kCount; ++n)
    if (Moments::index(kMonomials[n].i, kMonomials[n].j, kMonomials[n].k) != n) return false;
  return true;
}());

Eigen::Vector3d Moments::centroid() const {
  if (!(values_[0] > 0)) return origin_;
  return origin_ + Eigen::Vector3d(values_[index(1, 0, 0)], values_[index(0, 1, 0)],
                                   values_[index(0, 0, 1)]) /
                       values_[0];
}

void Moments::add_offset(const Eigen::Vector3d& d, double w, int max_degree) {
  double px[5], py[5], pz[5];
  px[0] = py[0] = pz[0] = 1;
  for (int p = 1; p <= 4; ++p) {
    px[p] = px[p - 1] * d.x();
    py[p] = py[p - 1] * d.y();
    pz[p] = pz[p - 1] * d.z();
  }
  if (max_degree >= 4)
    add_monomials(std::make_index_sequence<kCount>(), px, py, pz, w, values_.data());
  else
    add_monomials(std::make_index_sequence<kCountUpToDegree2>(), px, py, pz, w, values_.data());
}

Moments Moments::translated(const Eigen::Vector3d& new_origin, int max_degree) const {
  // Σ w (y − d)^α with y = x − o and d = o' − o: each target monomial α is a fixed combination
  // Σ_β C(α, β) (−d)^(α−β) M_β over sub-monomials β ≤ α, listed once in kTranslationTerms.
  if (new_origin == origin_ && max_degree >= 4) return *this;
  const Eigen::Vector3d d = new_origin - origin_;
  double px[5], py[5], pz[5];
  px[0] = py[0] = pz[0] = 1;
  for (int p = 1; p <= 4; ++p) {
    px[p] = px[p - 1] * -d.x();
    py[p] = py[p - 1] * -d.y();
    pz[p] = pz[p - 1] * -d.z();
  }
  double shift[kCount];
  for (int n = 0; n < kCount; ++n)
    shift[n] = px[kMonomials[n].i] * py[kMonomials[n].j] * pz[kMonomials[n].k];
  Moments result(new_origin);
  // Terms are listed by target monomial, and monomials by degree. Unrolled at compile time: with
  // constant indices the compiler interleaves the 35 independent sums (each still added in the
  // listed order, so results are the same bit for bit).
  // Moments about their centroid (as every cluster's are in the hierarchy) skip the terms of the
  // zero first moments.
  const double* source = values_.data();
  double* target = result.values_.data();
  const bool centred = values_[1] == 0 && values_[2] == 0 && values_[3] == 0;
  if (centred && max_degree >= 4)
    apply_translation_terms<kCentredTerms>(std::make_index_sequence<kCentredTerms.size()>(), shift,
                                           source, target);
  else if (centred)
    apply_translation_terms<kCentredTerms>(std::make_index_sequence<kCentredTermsUpToDegree2>(),
                                           shift, source, target);
  else if (max_degree >= 4)
    apply_translation_terms<kTranslationTerms>(std::make_index_sequence<kTranslationTerms.size()>(),
                                               shift, source, target);
  else
    apply_translation_terms<kTranslationTerms>(std::make_index_sequence<kTermsUpToDegree2>(), shift,
                                               source, target);
  return result;
}

Moments& Moments::add(const Moments& other, int max_degree) {
  const int count = max_degree >= 4 ? kCount : kCountUpToDegree2;
  if (other.origin_ == origin_) {
    for (int n = 0; n < count; ++n) values_[n] += other.values_[n];
  } else {
    const Moments moved = other.translated(origin_, max_degree);
    for (int n = 0; n < count; ++n) values_[n] += moved.values_[n];
  }
  if (count < kCount) std::fill(values_.begin() + count, values_.end(), 0.0);
  return *this;
}

Eigen::Matrix3d Moments::second_moment() const {
  Eigen::Matrix3d s;
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b) s(a, b) = s(b, a) = values_[axes(a, b)];
  return s;
}

Eigen::Vector3d Moments::third_moment_contracted(const Eigen::Matrix3d& q) const {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c) v[a] += q(b, c) * values_[axes(a, b, c)];
  return v;
}

double Moments::fourth_moment_contracted(const Eigen::Matrix3d& q) const {
  double sum = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) sum += q(a, b) * q(c, d) * values_[axes(a, b, c, d)];
  return sum;
}

void ClusterStats::merge(const ClusterStats& other, const EdgeStats& shared_edges, int max_degree) {
  // (c − o) = (c − o_other) + (o_other − o).
  normal_position += other.normal_position +
                     (other.moments.origin() - moments.origin()) * other.normal_sum.transpose();
  face_planes += other.face_planes.translated(moments.origin() - other.moments.origin());
  moments.add(other.moments, max_degree);
  edges += other.edges;
  edges += shared_edges;
  normal_sum += other.normal_sum;
  area += other.area;
  triangle_count += other.triangle_count;
  samples.merge(other.samples);
}

bool FaceCorners::unite(const FaceCorners& a, const FaceCorners& b, const EdgeStats& shared,
                        FaceCorners& united) {
  if (a.triangle_count + b.triangle_count > kMaxTriangles) return false;
  const double w = a.weight + b.weight;
  const detail::UnionPlacement placement =
      detail::place_union(a.weight, a.centroid, b.weight, b.centroid, w);
  const Eigen::Vector3d &shift_a = placement.shift_a, &shift_b = placement.shift_b;
  united.centroid = placement.centroid;
  united.second_moment = a.second_moment + b.second_moment;
  united.second_moment += placement.second_moment_gain;
  // Each part's triangles after the ones before; a part of one triangle (nearly every face) by a
  // call with a constant count, which the compiler unrolls.
  const auto append = [&united](const FaceCorners& part, const Eigen::Vector3d& shift,
                                std::uint32_t to, std::uint32_t count) {
    for (std::uint32_t t = 0; t < count; ++t, ++to) {
      for (int k = 0; k < 3; ++k) {
        united.offsets[3 * to + k] = part.offsets[3 * t + k] + shift;
        united.weights[3 * to + k] = part.weights[3 * t + k];
      }
      united.area_normals[to] = part.area_normals[t];
      united.areas[to] = part.areas[t];
      united.triangle_offsets[to] = part.triangle_offsets[t] + shift;
    }
  };
  if (a.triangle_count == 1 && b.triangle_count == 1) {
    append(a, shift_a, 0, 1);
    append(b, shift_b, 1, 1);
  } else {
    append(a, shift_a, 0, a.triangle_count);
    append(b, shift_b, a.triangle_count, b.triangle_count);
  }
  united.triangle_count = a.triangle_count + b.triangle_count;
  united.weight = w;
  united.normal_sum = a.normal_sum + b.normal_sum;
  united.normal_position = a.normal_position + shift_a * a.normal_sum.transpose() +
                           b.normal_position + shift_b * b.normal_sum.transpose();
  united.area = a.area + b.area;
  united.edges = a.edges;
  united.edges += b.edges;
  united.edges += shared;
  return true;
}

void ClusterStats::add(const FaceCorners& face, int max_degree) {
  const Eigen::Vector3d shift = face.centroid - moments.origin();
  for (std::uint32_t k = 0; k < face.corner_count(); ++k)
    moments.add_offset(face.offsets[k] + shift, face.weights[k], max_degree);
  normal_position += face.normal_position + shift * face.normal_sum.transpose();
  for (std::uint32_t t = 0; t < face.triangle_count; ++t)
    if (face.areas[t] > 0)
      face_planes.add_face(face.area_normals[t] / face.areas[t], face.areas[t],
                           face.triangle_offsets[t] + shift);
  edges += face.edges;
  normal_sum += face.normal_sum;
  area += face.area;
  triangle_count += face.triangle_count;
}

ClusterStats ClusterStats::translated(const Eigen::Vector3d& new_origin, int max_degree) const {
  ClusterStats result = *this;
  result.normal_position -= (new_origin - moments.origin()) * normal_sum.transpose();
  result.face_planes = face_planes.translated(new_origin - moments.origin());
  result.moments = moments.translated(new_origin, max_degree);
  return result;
}

double ClusterStats::normal_alignment(const Eigen::Matrix3d& q, const Eigen::Vector3d& point,
                                      double radius) const {
  if (!(area > 0) || !(radius > 0)) return 0;
  // Σ A n · Q (c − p) = tr(Q Σ (c − o) (A n)ᵀ) − (A n)ᵀ Q (p − o), summed over triangles.
  const double sum = (q * normal_position).trace() - normal_sum.dot(q * (point - moments.origin()));
  return std::abs(sum) / (radius * area);
}

void FacePlaneStats::add_face(const Eigen::Vector3d& n, double area,
                              const Eigen::Vector3d& centroid_offset) {
  const double offset = n.dot(centroid_offset);
  normal_normal[0] += area * n.x() * n.x();
  normal_normal[1] += area * n.x() * n.y();
  normal_normal[2] += area * n.x() * n.z();
  normal_normal[3] += area * n.y() * n.y();
  normal_normal[4] += area * n.y() * n.z();
  normal_normal[5] += area * n.z() * n.z();
  normal_offset += (area * offset) * n;
  offset_square += area * offset * offset;
}

FacePlaneStats FacePlaneStats::translated(const Eigen::Vector3d& shift) const {
  // n·(c − o − d) = n·(c − o) − n·d, summed with the weights A n and A.
  if (shift.isZero(0)) return *this;
  const Eigen::Vector3d nd = normal_normal_matrix() * shift;  // Σ A n (n·d)
  FacePlaneStats result = *this;
  result.normal_offset -= nd;
  result.offset_square += -2 * normal_offset.dot(shift) + shift.dot(nd);
  return result;
}

FacePlaneStats& FacePlaneStats::operator+=(const FacePlaneStats& other) {
  for (int n = 0; n < 6; ++n) normal_normal[n] += other.normal_normal[n];
  normal_offset += other.normal_offset;
  offset_square += other.offset_square;
  return *this;
}

Eigen::Matrix3d FacePlaneStats::normal_normal_matrix() const {
  Eigen::Matrix3d m;
  m << normal_normal[0], normal_normal[1], normal_normal[2], normal_normal[1], normal_normal[3],
      normal_normal[4], normal_normal[2], normal_normal[4], normal_normal[5];
  return m;
}

namespace {
// Kept order: higher priority first; equal priorities keep their order (stable merges).
bool before(const SurfaceSample& a, const SurfaceSample& b) {
  return a.priority > b.priority;
}
}  // namespace

void SampleReservoir::add(const SurfaceSample& sample) {
  if (samples.size() > kCapacity && !before(sample, samples.back())) return;
  const auto at = std::upper_bound(samples.begin(), samples.end(), sample, before);
  samples.insert(at, sample);
  if (samples.size() > kCapacity + 1) samples.pop_back();
}

void SampleReservoir::merge(const SampleReservoir& other) {
  if (other.samples.empty()) return;
  std::vector<SurfaceSample> merged;
  merged.reserve(std::min(samples.size() + other.samples.size(), kCapacity + 1));
  auto a = samples.cbegin();
  auto b = other.samples.cbegin();
  while (merged.size() < kCapacity + 1 && (a != samples.cend() || b != other.samples.cend())) {
    if (b == other.samples.cend() || (a != samples.cend() && !before(*b, *a)))
      merged.push_back(*a++);
    else
      merged.push_back(*b++);
  }
  samples = std::move(merged);
}

double SampleReservoir::estimator_weight(std::size_t i) const {
  return std::max(samples[i].weight, threshold());
}

double SampleReservoir::priority_of(std::uint64_t corner_id, double weight) {
  // splitmix64 of the corner's index: u uniform in (0, 1], the same in every run and merge order.
  std::uint64_t z = corner_id + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  const double u = static_cast<double>((z >> 11) + 1) * 0x1.0p-53;
  return weight / u;
}

EdgeStats& EdgeStats::operator+=(const EdgeStats& other) {
  for (int n = 0; n < 6; ++n) tensor[n] += other.tensor[n];
  return *this;
}

Eigen::Matrix3d EdgeStats::tensor_matrix() const {
  Eigen::Matrix3d t;
  t << tensor[0], tensor[1], tensor[2], tensor[1], tensor[3], tensor[4], tensor[2], tensor[4],
      tensor[5];
  return t;
}

void EdgeStats::add_edge(const Eigen::Vector3d& edge, double beta) {
  const double edge_length = edge.norm();
  if (!(edge_length > 0)) return;
  // |e| β ê êᵀ = (β / |e|) e eᵀ.
  const double s = beta / edge_length;
  tensor[0] += s * edge.x() * edge.x();
  tensor[1] += s * edge.x() * edge.y();
  tensor[2] += s * edge.x() * edge.z();
  tensor[3] += s * edge.y() * edge.y();
  tensor[4] += s * edge.y() * edge.z();
  tensor[5] += s * edge.z() * edge.z();
}

}  // namespace primseg
