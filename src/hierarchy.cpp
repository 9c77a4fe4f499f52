#include "primseg/hierarchy.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "model_selection.hpp"
#include "parallel.hpp"
#include "primseg/error.hpp"

namespace primseg {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// Candidate merges ordered by (cost, primitive type, degree of the merged node, smaller id, larger
// id). On equal cost (in practice: zero, exact fits) simpler types go first, so flat regions are
// whole before exact curved fits can reach into them. The version only tells stale entries
// apart; it never decides between live ones.
//
// Lazy evaluation adds entries whose cost is only a lower bound of the candidate's (exact =
// false). At equal cost a bound comes before every exact entry, so when an exact entry reaches
// the top every bound left is strictly above it: it is the same minimum the eager scheme finds.
struct HeapEntry {
  double cost;
  PrimitiveType type;
  bool exact;
  std::uint32_t degree;
  std::uint32_t low, high;
  std::uint32_t edge;
  std::uint32_t version;
};

// std heaps are max-heaps: "a after b" puts the smallest key on top.
bool comes_after(const HeapEntry& a, const HeapEntry& b) {
  if (a.cost != b.cost) return a.cost > b.cost;
  if (a.exact != b.exact) return a.exact;
  if (a.type != b.type) return a.type > b.type;
  if (a.degree != b.degree) return a.degree > b.degree;
  if (a.low != b.low) return a.low > b.low;
  if (a.high != b.high) return a.high > b.high;
  return a.version > b.version;
}

struct LiveEdge {
  std::uint32_t a, b;  // current node ids of the two clusters
  std::uint32_t version = 0;
  bool alive = true;
  EdgeStats shared;  // the mesh edges between the two clusters
  // A lower bound of the cost of merging any two clusters that contain a and b (lazy only).
  double cost_bound = 0;
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Hierarchy

Hierarchy::Hierarchy(std::shared_ptr<const Mesh> mesh, HierarchyOptions options,
                     std::vector<Merge> merges)
    : Hierarchy(std::move(mesh), std::move(options), std::move(merges), nullptr) {}

Hierarchy::Hierarchy(std::shared_ptr<const Mesh> mesh, HierarchyOptions options,
                     std::vector<Merge> merges, std::unique_ptr<DualGraph> graph)
    : mesh_(std::move(mesh)),
      options_(std::move(options)),
      graph_(std::move(graph)),
      merges_(std::move(merges)) {
  validate(options_);
  if (!mesh_ || mesh_->face_count() == 0) throw InvalidInputError("mesh has no faces");
  const std::uint32_t f = mesh_->face_count();
  if (merges_.size() != f - 1)
    throw InvalidInputError("a hierarchy of " + std::to_string(f) + " faces needs " +
                            std::to_string(f - 1) + " merges, not " +
                            std::to_string(merges_.size()));
  if (!graph_) graph_ = std::make_unique<DualGraph>(*mesh_, options_.weights);
  parents_.assign(2 * std::size_t{f} - 1, kNone);
  for (std::uint32_t i = 0; i < merges_.size(); ++i) {
    const Merge& m = merges_[i];
    const std::uint32_t node = f + i;
    if (m.first >= node || m.second >= node || m.first == m.second || parents_[m.first] != kNone ||
        parents_[m.second] != kNone)
      throw InvalidInputError("merge " + std::to_string(i) + " does not form a binary tree");
    parents_[m.first] = parents_[m.second] = node;
  }
}

namespace {

// Leaves are not stored: their fit is recomputed from the face, by the same rule as merges.
detail::SelectedModel select_leaf(const HierarchyOptions& options, const DualGraph& graph,
                                  std::uint32_t face) {
  const detail::ModelSelector selector(options);
  return selector.select(graph.face_stats(face, selector.needs_samples()).centred());
}

}  // namespace

Primitive Hierarchy::primitive(std::uint32_t node) const {
  if (!is_leaf(node)) return merges_[node - face_count()].primitive;
  return graph_->frame().to_input(select_leaf(options_, *graph_, node).fit.primitive);
}

double Hierarchy::error(std::uint32_t node) const {
  if (!is_leaf(node)) return merges_[node - face_count()].error;
  return select_leaf(options_, *graph_, node).fit.error;
}

double Hierarchy::weight(std::uint32_t node) const {
  if (!is_leaf(node)) return merges_[node - face_count()].weight;
  return graph_->face_stats(node).moments.weight();
}

std::uint32_t Hierarchy::face_count(std::uint32_t node) const {
  return is_leaf(node) ? 1 : merges_[node - face_count()].face_count;
}

double Hierarchy::rms_estimate(std::uint32_t node) const {
  const double w = weight(node);
  if (!(w > 0)) return 0;
  return std::ldexp(std::sqrt(error(node) / w), graph_->frame().exponent);
}

std::vector<std::array<double, 4>> Hierarchy::linkage() const {
  std::vector<std::array<double, 4>> rows(merges_.size());
  for (std::size_t i = 0; i < merges_.size(); ++i)
    rows[i] = {double(merges_[i].first), double(merges_[i].second), merges_[i].cost,
               double(merges_[i].face_count)};
  return rows;
}

// ---------------------------------------------------------------------------------------------
// HierarchyBuilder

class HierarchyBuilder::Impl {
 public:
  Impl(std::shared_ptr<const Mesh> mesh, HierarchyOptions options)
      : mesh_(std::move(mesh)), options_(std::move(options)), selector_(options_) {
    if (!mesh_) throw InvalidInputError("no mesh");
    mesh_->validate();
    graph_ = std::make_unique<DualGraph>(*mesh_, options_.weights);
    const std::uint32_t f = mesh_->face_count();
    const unsigned threads = detail::thread_count(options_.threads);
    // Statistics are stored for merged clusters only (at most F / 2 live at once); a single
    // face's are recomputed when needed, which costs less than a fit.
    stats_index_of_slot_.assign(f, kNone);
    stats_.reserve(f / 2 + 1);  // address space only: pages are touched as clusters form
    merges_.reserve(f - 1);
    slot_of_node_.assign(2 * std::size_t{f}, kNone);
    for (std::uint32_t face = 0; face < f; ++face) slot_of_node_[face] = face;
    face_count_of_slot_.assign(f, 1);
    min_face_of_slot_.resize(f);
    for (std::uint32_t face = 0; face < f; ++face) min_face_of_slot_[face] = face;
    if (options_.exact_costs) {
      next_face_.assign(f, kNone);
      list_head_.resize(f);
      list_tail_.resize(f);
      for (std::uint32_t face = 0; face < f; ++face) list_head_[face] = list_tail_[face] = face;
    }

    adjacency_.resize(f);
    edges_.reserve(graph_->edges().size());
    for (const DualEdge& e : graph_->edges()) {
      const auto id = static_cast<std::uint32_t>(edges_.size());
      edges_.push_back({e.first, e.second, 0, true, e.shared});
      adjacency_[e.first].push_back(id);
      adjacency_[e.second].push_back(id);
    }
    stamp_.assign(2 * std::size_t{f}, 0);
    marker_.assign(2 * std::size_t{f}, kNone);
    // Every candidate's cost is independent of the others: evaluate them in parallel, then the
    // degrees (which share scratch arrays) in order.
    lazy_ = options_.evaluation != CandidateEvaluation::Eager && !options_.exact_costs;
    max_penalty_ = *std::max_element(options_.type_penalty.begin(), options_.type_penalty.end());
    heap_.resize(edges_.size());
    detail::parallel_for(edges_.size(), threads, [&](std::size_t id) {
      heap_[id] = evaluate(static_cast<std::uint32_t>(id));
    });
    for (HeapEntry& entry : heap_) entry.degree = merged_degree(entry.low, entry.high);
    evaluations_ = heap_.size();
    std::make_heap(heap_.begin(), heap_.end(), comes_after);
    live_edges_ = static_cast<std::uint32_t>(edges_.size());
    total_merges_ = f - graph_->component_count();
  }

  bool step() {
    while (!heap_.empty()) {
      std::pop_heap(heap_.begin(), heap_.end(), comes_after);
      HeapEntry entry = heap_.back();
      heap_.pop_back();
      const LiveEdge& edge = edges_[entry.edge];
      if (!edge.alive || edge.version != entry.version) continue;
      if (!entry.exact) {
        // A bound reached the top: evaluate the candidate. It keeps the degree it was queued
        // with, as the eager scheme's entry would have.
        const std::uint32_t degree = entry.degree;
        entry = evaluate(entry.edge);
        ++evaluations_;
        entry.degree = degree;
        heap_.push_back(entry);
        std::push_heap(heap_.begin(), heap_.end(), comes_after);
        continue;
      }
      // Neighbours of the two clusters may have merged since this entry was pushed, which only
      // lowers the merged degree: requeue with the current one so the tie rule sees it.
      const std::uint32_t degree = merged_degree(edge.a, edge.b);
      if (degree != entry.degree) {
        entry.degree = degree;
        heap_.push_back(entry);
        std::push_heap(heap_.begin(), heap_.end(), comes_after);
        continue;
      }
      merge(entry.edge);
      return true;
    }
    return false;
  }

  std::uint32_t merge_count() const { return static_cast<std::uint32_t>(merges_.size()); }
  std::uint32_t total_merge_count() const { return total_merges_; }
  std::uint64_t evaluation_count() const { return evaluations_; }

  struct Parts {
    std::shared_ptr<const Mesh> mesh;
    HierarchyOptions options;
    std::vector<Merge> merges;
    std::unique_ptr<DualGraph> graph;
  };

  Parts finish(const std::function<void(double)>& progress) {
    if (!graph_) throw Error("HierarchyBuilder::finish() was already called");
    const std::uint32_t report_every = std::max<std::uint32_t>(1, total_merges_ / 100);
    if (progress) progress(0);
    while (step())
      if (progress && merges_.size() % report_every == 0)
        progress(double(merges_.size()) / std::max<std::uint32_t>(1, total_merges_));
    add_trailing_merges();
    if (progress) progress(1);
    return {std::move(mesh_), std::move(options_), std::move(merges_), std::move(graph_)};
  }

 private:
  std::uint32_t next_node() const {
    return mesh_->face_count() + static_cast<std::uint32_t>(merges_.size());
  }

  std::uint32_t other_end(const LiveEdge& e, std::uint32_t node) const {
    return e.a == node ? e.b : e.a;
  }

  // Number of clusters adjacent to a ∪ b; drops dead edges from the two lists on the way.
  std::uint32_t merged_degree(std::uint32_t a, std::uint32_t b) {
    ++current_stamp_;
    std::uint32_t degree = 0;
    for (std::uint32_t node : {a, b}) {
      std::vector<std::uint32_t>& list = adjacency_[slot_of_node_[node]];
      std::erase_if(list, [&](std::uint32_t id) { return !edges_[id].alive; });
      for (std::uint32_t id : list) {
        const std::uint32_t other = other_end(edges_[id], node);
        if (other == a || other == b || stamp_[other] == current_stamp_) continue;
        stamp_[other] = current_stamp_;
        ++degree;
      }
    }
    return degree;
  }

  // A live cluster's statistics: stored for a merged cluster, computed into `leaf` for a face
  // (whose slot is its face id).
  const ClusterStats& stats_of(std::uint32_t node, ClusterStats& leaf) const {
    const std::uint32_t slot = slot_of_node_[node];
    const std::uint32_t index = stats_index_of_slot_[slot];
    if (index != kNone) return stats_[index];
    leaf = graph_->face_stats(slot, selector_.needs_samples());
    return leaf;
  }

  void store_stats(std::uint32_t slot, ClusterStats&& stats) {
    std::uint32_t& index = stats_index_of_slot_[slot];
    if (index == kNone) {
      if (free_stats_.empty()) {
        index = static_cast<std::uint32_t>(stats_.size());
        stats_.push_back(std::move(stats));
        return;
      }
      index = free_stats_.back();
      free_stats_.pop_back();
    }
    stats_[index] = std::move(stats);
  }

  void release_stats(std::uint32_t slot) {
    std::uint32_t& index = stats_index_of_slot_[slot];
    if (index != kNone) free_stats_.push_back(index);
    index = kNone;
  }

  // The statistics of a ∪ b, moments up to the degree the fits will use (all of them when the
  // result is kept).
  ClusterStats union_stats(const LiveEdge& e, bool keep) const {
    ClusterStats leaf_a, leaf_b;
    const ClusterStats& a = stats_of(e.a, leaf_a);
    const ClusterStats& b = stats_of(e.b, leaf_b);
    const int degree = keep ? 4 : selector_.moment_degree(a.triangle_count + b.triangle_count);
    ClusterStats stats = a;
    stats.merge(b, e.shared, degree);
    return stats;
  }

  detail::SelectedModel select(const ClusterStats& stats, const LiveEdge& e) const {
    const ClusterStats centred_stats = stats.centred(selector_.moment_degree(stats.triangle_count));
    if (!options_.exact_costs) return selector_.select(centred_stats);
    const detail::ExactError exact = [&](const Primitive& primitive) {
      double sum = 0;
      for (std::uint32_t node : {e.a, e.b})
        for (std::uint32_t f = list_head_[slot_of_node_[node]]; f != kNone; f = next_face_[f])
          for (std::uint32_t t = graph_->first_triangle(f); t < graph_->first_triangle(f + 1);
               ++t) {
            const std::array<double, 3> w = graph_->corner_weights(t);
            for (int c = 0; c < 3; ++c) {
              const Eigen::Vector3d& x = graph_->position(mesh_->triangles[t][c]);
              const double d = primitive.distance({x.x(), x.y(), x.z()});
              sum += w[c] * d * d;
            }
          }
      return sum;
    };
    return selector_.select(centred_stats, &exact);
  }

  // A candidate's entry without its degree. Reads shared state and writes only this edge's
  // bound (safe in parallel over distinct edges).
  HeapEntry evaluate(std::uint32_t id) {
    LiveEdge& e = edges_[id];
    const detail::SelectedModel model = select(union_stats(e, false), e);
    if (lazy_) e.cost_bound = std::max(e.cost_bound, model.superset_cost_bound);
    return {model.cost,         model.fit.primitive.type, true, 0,
            std::min(e.a, e.b), std::max(e.a, e.b),       id,   e.version};
  }

  // The edge's cost bound if it holds for the current union, else 0. A cost that would snap to
  // zero (at most zero_cost_tolerance × the union's spread, for the cheapest type) can be below
  // any bound from a subset, so the bound holds only above that level. The union's spread is
  // exact from the parts' (Σ w |x − c|² adds a w_a w_b / (w_a + w_b) |c_a − c_b|² term); the
  // factor 2 covers round-off.
  double queued_bound(const LiveEdge& e) const {
    if (!(e.cost_bound > 0)) return 0;
    ClusterStats leaf_a, leaf_b;
    const Moments& a = stats_of(e.a, leaf_a).moments;
    const Moments& b = stats_of(e.b, leaf_b).moments;
    const double wa = a.weight(), wb = b.weight();
    if (!(wa > 0) || !(wb > 0)) return 0;
    const double spread = centred_spread(a) + centred_spread(b) +
                          wa * wb / (wa + wb) * (a.centroid() - b.centroid()).squaredNorm();
    return e.cost_bound > 2 * max_penalty_ * options_.zero_cost_tolerance * spread ? e.cost_bound
                                                                                   : 0.0;
  }

  static double centred_spread(const Moments& m) {
    const Eigen::Vector3d first(m.at(1, 0, 0), m.at(0, 1, 0), m.at(0, 0, 1));
    return m.at(2, 0, 0) + m.at(0, 2, 0) + m.at(0, 0, 2) - first.squaredNorm() / m.weight();
  }

  HeapEntry candidate(std::uint32_t id) {
    HeapEntry entry = evaluate(id);
    ++evaluations_;
    entry.degree = merged_degree(edges_[id].a, edges_[id].b);
    return entry;
  }

  void merge(std::uint32_t edge_id) {
    LiveEdge& edge = edges_[edge_id];
    const std::uint32_t a = edge.a, b = edge.b;
    const std::uint32_t slot_a = slot_of_node_[a], slot_b = slot_of_node_[b];
    ClusterStats merged = union_stats(edge, true);
    const detail::SelectedModel model = select(merged, edge);
    const std::uint32_t node = next_node();

    Merge record;
    record.first = std::min(a, b);
    record.second = std::max(a, b);
    record.cost = model.cost;
    record.error = model.fit.error;
    record.weight = merged.moments.weight();
    record.face_count = face_count_of_slot_[slot_a] + face_count_of_slot_[slot_b];
    record.primitive = graph_->frame().to_input(model.fit.primitive);
    merges_.push_back(record);
    max_cost_ = std::max(max_cost_, model.cost);

    // The merged cluster lives in a's slot; b's is released.
    release_stats(slot_b);
    store_stats(slot_a, std::move(merged));
    face_count_of_slot_[slot_a] = record.face_count;
    min_face_of_slot_[slot_a] = std::min(min_face_of_slot_[slot_a], min_face_of_slot_[slot_b]);
    slot_of_node_[node] = slot_a;
    slot_of_node_[a] = slot_of_node_[b] = kNone;
    if (options_.exact_costs) {
      next_face_[list_tail_[slot_a]] = list_head_[slot_b];
      list_tail_[slot_a] = list_tail_[slot_b];
    }
    edge.alive = false;
    --live_edges_;

    // Rename a and b to the new node; two edges to a common neighbour become one.
    std::vector<std::uint32_t> kept;
    kept.reserve(adjacency_[slot_a].size() + adjacency_[slot_b].size());
    for (std::uint32_t old : {a, b}) {
      const std::uint32_t slot = old == a ? slot_a : slot_b;
      for (std::uint32_t id : adjacency_[slot]) {
        LiveEdge& e = edges_[id];
        if (!e.alive) continue;
        const std::uint32_t other = other_end(e, old);
        if (marker_[other] == kNone) {
          marker_[other] = id;
          (e.a == old ? e.a : e.b) = node;
          kept.push_back(id);
        } else {
          LiveEdge& into = edges_[marker_[other]];
          into.shared += e.shared;
          into.cost_bound = std::max(into.cost_bound, e.cost_bound);
          e.alive = false;
          --live_edges_;
        }
      }
    }
    for (std::uint32_t id : kept) marker_[other_end(edges_[id], node)] = kNone;
    adjacency_[slot_a] = std::move(kept);
    std::vector<std::uint32_t>().swap(adjacency_[slot_b]);

    for (std::uint32_t id : adjacency_[slot_a]) {
      LiveEdge& e = edges_[id];
      ++e.version;
      // A zero bound would reach the top before the next merge anyway: evaluate it now.
      const double bound = lazy_ ? queued_bound(e) : 0;
      if (bound > 0)
        heap_.push_back({bound, PrimitiveType::Plane, false, merged_degree(e.a, e.b),
                         std::min(e.a, e.b), std::max(e.a, e.b), id, e.version});
      else
        heap_.push_back(candidate(id));
      std::push_heap(heap_.begin(), heap_.end(), comes_after);
    }
    compact_heap_if_stale();
  }

  // Re-evaluated candidates leave their old entries behind; drop them once they outnumber the
  // live ones. The pop order does not change: live entries have distinct keys.
  void compact_heap_if_stale() {
    if (heap_.size() <= 2 * std::size_t{live_edges_} + 1024) return;
    std::erase_if(heap_, [&](const HeapEntry& entry) {
      const LiveEdge& e = edges_[entry.edge];
      return !e.alive || e.version != entry.version;
    });
    std::make_heap(heap_.begin(), heap_.end(), comes_after);
  }

  // Components are joined in the order of their lowest face, each trailing merge costed above
  // every real one so that cuts and dendrograms keep them last.
  void add_trailing_merges() {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> roots;  // (lowest face, node)
    for (std::uint32_t node = 0; node < next_node(); ++node)
      if (slot_of_node_[node] != kNone)
        roots.push_back({min_face_of_slot_[slot_of_node_[node]], node});
    std::sort(roots.begin(), roots.end());
    const double cost = max_cost_ > 0 ? 2 * max_cost_ : 1.0;
    std::uint32_t joined = roots.front().second;
    ClusterStats leaf;
    double weight = stats_of(joined, leaf).moments.weight();
    std::uint32_t faces = face_count_of_slot_[slot_of_node_[joined]];
    for (std::size_t i = 1; i < roots.size(); ++i) {
      const std::uint32_t other = roots[i].second;
      Merge record;
      record.first = std::min(joined, other);
      record.second = std::max(joined, other);
      record.cost = cost;
      record.weight = weight += stats_of(other, leaf).moments.weight();
      record.face_count = faces += face_count_of_slot_[slot_of_node_[other]];
      record.trailing = true;
      joined = next_node();
      merges_.push_back(record);
    }
  }

  std::shared_ptr<const Mesh> mesh_;
  HierarchyOptions options_;
  detail::ModelSelector selector_;
  std::unique_ptr<DualGraph> graph_;
  std::vector<ClusterStats> stats_;                 // merged clusters' statistics, pooled
  std::vector<std::uint32_t> stats_index_of_slot_;  // into stats_; kNone for a single face
  std::vector<std::uint32_t> free_stats_;           // unused entries of stats_
  std::vector<std::uint32_t> slot_of_node_;
  std::vector<std::uint32_t> face_count_of_slot_;
  std::vector<std::uint32_t> min_face_of_slot_;
  std::vector<std::vector<std::uint32_t>> adjacency_;  // per slot: edge ids
  std::vector<LiveEdge> edges_;
  std::vector<HeapEntry> heap_;
  std::vector<Merge> merges_;
  std::vector<std::uint32_t> stamp_;
  std::uint32_t current_stamp_ = 0;
  std::vector<std::uint32_t> marker_;
  std::vector<std::uint32_t> next_face_, list_head_, list_tail_;  // exact_costs only
  std::uint32_t total_merges_ = 0;
  std::uint32_t live_edges_ = 0;
  double max_cost_ = 0;
  std::uint64_t evaluations_ = 0;
  bool lazy_ = false;
  double max_penalty_ = 0;
};

HierarchyBuilder::HierarchyBuilder(std::shared_ptr<const Mesh> mesh, HierarchyOptions options)
    : impl_(std::make_unique<Impl>(std::move(mesh), std::move(options))) {}
HierarchyBuilder::~HierarchyBuilder() = default;
bool HierarchyBuilder::step() {
  return impl_->step();
}
std::uint32_t HierarchyBuilder::merge_count() const {
  return impl_->merge_count();
}
std::uint32_t HierarchyBuilder::total_merge_count() const {
  return impl_->total_merge_count();
}
std::uint64_t HierarchyBuilder::evaluation_count() const {
  return impl_->evaluation_count();
}
Hierarchy HierarchyBuilder::finish(const std::function<void(double)>& progress) {
  Impl::Parts parts = impl_->finish(progress);
  return Hierarchy(std::move(parts.mesh), std::move(parts.options), std::move(parts.merges),
                   std::move(parts.graph));
}

Hierarchy build_hierarchy(const Mesh& mesh, const HierarchyOptions& options) {
  return build_hierarchy(std::make_shared<const Mesh>(mesh), options);
}

Hierarchy build_hierarchy(std::shared_ptr<const Mesh> mesh, const HierarchyOptions& options) {
  return HierarchyBuilder(std::move(mesh), options).finish();
}

}  // namespace primseg
