#include "primseg/hierarchy.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "model_selection.hpp"
#include "parallel.hpp"
#include "primseg/error.hpp"

namespace primseg {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kPairTag = 1u << 31;

// Candidate merges ordered by (cost, primitive type, degree of the merged node, smaller id, larger
// id). On equal cost (in practice: zero, exact fits) simpler types go first, so flat regions are
// whole before exact curved fits can reach into them.
//
// Lazy evaluation adds entries whose cost is only a lower bound of the candidate's (exact =
// false). At equal cost a bound comes before every exact entry, so when an exact entry reaches
// the top every bound left is strictly above it: it is the same minimum the eager scheme finds.
//
// 24 bytes, as the heap holds up to 1.25 entries per live edge. An entry is stale once either
// cluster has merged: node ids are never reused, so (low, high) tells it apart from the edge's
// current clusters, and live entries have distinct keys.
struct HeapEntry {
  static constexpr std::uint32_t kMaxDegree = (1u << 28) - 1;

  double cost;
  // exact (bit 31), primitive type (bits 28 to 30), merged degree (bits 0 to 27, saturated at
  // kMaxDegree: a cluster with 2^28 neighbours is beyond any mesh this ranks), so that comparing
  // ranks compares (exact, type, degree).
  std::uint32_t rank;
  std::uint32_t low, high;
  std::uint32_t edge;

  HeapEntry() = default;
  HeapEntry(double key_cost, bool is_exact, PrimitiveType type, std::uint32_t merged_degree,
            std::uint32_t a, std::uint32_t b, std::uint32_t edge_id)
      : cost(key_cost),
        rank(std::uint32_t{is_exact} << 31 | static_cast<std::uint32_t>(type) << 28),
        low(std::min(a, b)),
        high(std::max(a, b)),
        edge(edge_id) {
    set_degree(merged_degree);
  }
  bool exact() const { return (rank >> 31) != 0; }
  std::uint32_t degree() const { return rank & kMaxDegree; }
  void set_degree(std::uint32_t merged_degree) {
    rank = (rank & ~kMaxDegree) | std::min(merged_degree, kMaxDegree);
  }
};
static_assert(sizeof(HeapEntry) == 24);
static_assert(kPrimitiveTypeCount <= 8);

// std heaps are max-heaps: "a after b" puts the smallest key on top.
bool comes_after(const HeapEntry& a, const HeapEntry& b) {
  if (a.cost != b.cost) return a.cost > b.cost;
  if (a.rank != b.rank) return a.rank > b.rank;
  if (a.low != b.low) return a.low > b.low;
  return a.high > b.high;
}

// 16 bytes: the builder keeps one per dual edge.
struct LiveEdge {
  std::uint32_t a, b;  // current node ids of the two clusters; a = kNone once dead
  // The mesh edges between the two clusters are those of the input dual edge with this id until
  // two edges to a common neighbour are combined; then their sum lives in a pool at this index.
  std::uint32_t combined_shared = kNone;
  // A lower bound of the cost of merging any two clusters that contain a and b (lazy only),
  // rounded down to a float: a looser bound costs an evaluation, never a different tree.
  float cost_bound = 0;

  bool alive() const { return a != kNone; }
  bool is_current(const HeapEntry& entry) const {
    return alive() && std::min(a, b) == entry.low && std::max(a, b) == entry.high;
  }
  void raise_cost_bound(double bound) {
    if (!(bound > cost_bound)) return;
    float rounded = static_cast<float>(std::min<double>(bound, std::numeric_limits<float>::max()));
    if (rounded > bound) rounded = std::nextafter(rounded, 0.0f);
    cost_bound = std::max(cost_bound, rounded);
  }
};
static_assert(sizeof(LiveEdge) == 16);

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
    // Statistics are stored for clusters of three faces or more only (at most F / 3 live at
    // once); a single face's or a pair's are recomputed when needed (see store_pair()).
    stats_index_of_slot_.assign(f, kNone);
    stats_.reserve(f / 3 + 1);  // address space only: pages are touched as clusters form
    merges_.reserve(f - 1);
    slot_of_node_.assign(2 * std::size_t{f}, kNone);
    for (std::uint32_t face = 0; face < f; ++face) slot_of_node_[face] = face;
    face_count_of_slot_.assign(f, 1);
    min_face_of_slot_.resize(f);
    for (std::uint32_t face = 0; face < f; ++face) min_face_of_slot_[face] = face;
    if (options_.exact_costs) {
      next_face_.assign(f, kNone);
      face_list_head_.resize(f);
      face_list_tail_.resize(f);
      for (std::uint32_t face = 0; face < f; ++face)
        face_list_head_[face] = face_list_tail_[face] = face;
    }

    const std::vector<DualEdge>& dual_edges = graph_->edges();
    if (dual_edges.size() >= kPairTag)
      throw InvalidInputError("mesh too large: more than 2^31 pairs of adjacent faces");
    edges_.reserve(dual_edges.size());
    for (const DualEdge& e : dual_edges) edges_.push_back({e.first, e.second});
    // Each face's list in increasing edge id: prepend in decreasing order.
    first_link_.assign(f, kNone);
    next_link_.resize(2 * dual_edges.size());
    for (std::size_t id = dual_edges.size(); id-- > 0;)
      for (std::uint32_t side = 0; side < 2; ++side) {
        const std::uint32_t face = side == 0 ? dual_edges[id].first : dual_edges[id].second;
        const auto link = static_cast<std::uint32_t>(2 * id + side);
        next_link_[link] = first_link_[face];
        first_link_[face] = link;
      }
    stamp_.assign(f, 0);
    marker_.assign(f, kNone);
    // Every candidate's cost is independent of the others: evaluate them in parallel, then the
    // degrees (which share scratch arrays) in order.
    lazy_ = options_.evaluation != CandidateEvaluation::Eager && !options_.exact_costs;
    max_penalty_ = *std::max_element(options_.type_penalty.begin(), options_.type_penalty.end());
    // Compaction keeps the heap within a quarter of the live edges of stale entries (plus one
    // merge's pushes), so it never outgrows this.
    heap_.reserve(heap_capacity(edges_.size()) + 64);
    heap_.resize(edges_.size());
    detail::parallel_for(edges_.size(), threads, [&](std::size_t id) {
      heap_[id] = evaluate(static_cast<std::uint32_t>(id));
    });
    for (HeapEntry& entry : heap_) entry.set_degree(merged_degree(entry.low, entry.high));
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
      if (!edge.is_current(entry)) continue;
      if (!entry.exact()) {
        // A bound reached the top: evaluate the candidate. It keeps the degree it was queued
        // with, as the eager scheme's entry would have.
        const std::uint32_t degree = entry.degree();
        entry = evaluate(entry.edge);
        ++evaluations_;
        entry.set_degree(degree);
        heap_.push_back(entry);
        std::push_heap(heap_.begin(), heap_.end(), comes_after);
        continue;
      }
      // Neighbours of the two clusters may have merged since this entry was pushed, which only
      // lowers the merged degree: requeue with the current one so the tie rule sees it.
      const std::uint32_t degree = merged_degree(edge.a, edge.b);
      if (degree != entry.degree()) {
        entry.set_degree(degree);
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
    release_working_memory();
    return {std::move(mesh_), std::move(options_), std::move(merges_), std::move(graph_)};
  }

 private:
  std::uint32_t next_node() const {
    return mesh_->face_count() + static_cast<std::uint32_t>(merges_.size());
  }

  std::uint32_t other_end(const LiveEdge& e, std::uint32_t node) const {
    return e.a == node ? e.b : e.a;
  }

  // Number of clusters adjacent to a ∪ b; unlinks dead edges from the two lists on the way.
  std::uint32_t merged_degree(std::uint32_t a, std::uint32_t b) {
    ++current_stamp_;
    std::uint32_t degree = 0;
    for (std::uint32_t node : {a, b}) {
      std::uint32_t* link = &first_link_[slot_of_node_[node]];
      while (*link != kNone) {
        const LiveEdge& e = edges_[*link / 2];
        if (!e.alive()) {
          *link = next_link_[*link];
          continue;
        }
        link = &next_link_[*link];
        const std::uint32_t other = other_end(e, node);
        if (other == a || other == b) continue;
        std::uint32_t& stamp = stamp_[slot_of_node_[other]];
        if (stamp == current_stamp_) continue;
        stamp = current_stamp_;
        ++degree;
      }
    }
    return degree;
  }

  // The mesh edges between the two clusters of live edge `id`.
  const EdgeStats& shared_edges(std::uint32_t id) const {
    const std::uint32_t pooled = edges_[id].combined_shared;
    return pooled == kNone ? graph_->edges()[id].shared : combined_shared_[pooled];
  }

  // Adds the mesh edges of `from` to those of `into` (their sum moves to the pool).
  void combine_shared_edges(std::uint32_t into, std::uint32_t from) {
    std::uint32_t& pooled = edges_[into].combined_shared;
    if (pooled == kNone) {
      const EdgeStats& original = graph_->edges()[into].shared;
      if (free_combined_shared_.empty()) {
        pooled = static_cast<std::uint32_t>(combined_shared_.size());
        combined_shared_.push_back(original);
      } else {
        pooled = free_combined_shared_.back();
        free_combined_shared_.pop_back();
        combined_shared_[pooled] = original;
      }
    }
    combined_shared_[pooled] += shared_edges(from);
  }

  void kill_edge(std::uint32_t id) {
    LiveEdge& e = edges_[id];
    if (e.combined_shared != kNone) free_combined_shared_.push_back(e.combined_shared);
    e.combined_shared = kNone;
    e.a = e.b = kNone;
    --live_edges_;
  }

  // A live cluster's statistics: stored for a merged cluster, computed into `leaf` for a face
  // (whose slot is its face id).
  // (computed into `leaf` for a face or a pair of faces, whose statistics are not stored).
  const ClusterStats& stats_of(std::uint32_t node, ClusterStats& leaf) const {
    const std::uint32_t slot = slot_of_node_[node];
    const std::uint32_t index = stats_index_of_slot_[slot];
    const bool samples = selector_.needs_samples();
    if (index == kNone) {
      leaf = graph_->face_stats(slot, samples);
    } else if (index == newest_pair_key_) {
      return newest_pair_;
    } else if (index & kPairTag) {
      // The same sum, in the same order, as union_stats() made when the pair merged.
      const DualEdge& e = graph_->edges()[index & ~kPairTag];
      leaf = graph_->face_stats(e.first, samples);
      leaf.merge(graph_->face_stats(e.second, samples), e.shared);
    } else {
      return stats_[index];
    }
    return leaf;
  }

  // Pairs of faces are most of the merged clusters alive at once (all of them at the peak on a
  // subdivided mesh, 40% on a scan): recomputing theirs from the two faces costs about a fifth
  // of a fit and saves their 568 bytes each. The newest pair's are kept, for the evaluation of
  // its candidates that follows.
  void store_pair(std::uint32_t slot, std::uint32_t edge_id, ClusterStats&& stats) {
    release_stats(slot);
    stats_index_of_slot_[slot] = newest_pair_key_ = kPairTag | edge_id;
    newest_pair_ = std::move(stats);
  }

  void store_stats(std::uint32_t slot, ClusterStats&& stats) {
    std::uint32_t& index = stats_index_of_slot_[slot];
    if (index == kNone || (index & kPairTag)) {
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
    if (index != kNone && !(index & kPairTag)) free_stats_.push_back(index);
    index = kNone;
  }

  // The statistics of a ∪ b, moments up to the degree the fits will use (all of them when the
  // result is kept).
  ClusterStats union_stats(std::uint32_t id, bool keep) const {
    const LiveEdge& e = edges_[id];
    ClusterStats leaf_a, leaf_b;
    const ClusterStats& a = stats_of(e.a, leaf_a);
    const ClusterStats& b = stats_of(e.b, leaf_b);
    const int degree = keep ? 4 : selector_.moment_degree(a.triangle_count + b.triangle_count);
    ClusterStats stats = a;
    stats.merge(b, shared_edges(id), degree);
    return stats;
  }

  detail::SelectedModel select(const ClusterStats& stats, const LiveEdge& e) const {
    const ClusterStats centred_stats = stats.centred(selector_.moment_degree(stats.triangle_count));
    if (!options_.exact_costs) return selector_.select(centred_stats);
    const detail::ExactError exact = [&](const Primitive& primitive) {
      double sum = 0;
      for (std::uint32_t node : {e.a, e.b})
        for (std::uint32_t f = face_list_head_[slot_of_node_[node]]; f != kNone; f = next_face_[f])
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
    const detail::SelectedModel model = select(union_stats(id, false), e);
    if (lazy_) e.raise_cost_bound(model.superset_cost_bound);
    return {model.cost, true, model.fit.primitive.type, 0, e.a, e.b, id};
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
    entry.set_degree(merged_degree(edges_[id].a, edges_[id].b));
    return entry;
  }

  void merge(std::uint32_t edge_id) {
    LiveEdge& edge = edges_[edge_id];
    const std::uint32_t a = edge.a, b = edge.b;
    const std::uint32_t slot_a = slot_of_node_[a], slot_b = slot_of_node_[b];
    ClusterStats merged = union_stats(edge_id, true);
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
    if (record.face_count == 2)
      store_pair(slot_a, edge_id, std::move(merged));
    else
      store_stats(slot_a, std::move(merged));
    face_count_of_slot_[slot_a] = record.face_count;
    min_face_of_slot_[slot_a] = std::min(min_face_of_slot_[slot_a], min_face_of_slot_[slot_b]);
    slot_of_node_[node] = slot_a;
    slot_of_node_[a] = slot_of_node_[b] = kNone;
    if (options_.exact_costs) {
      next_face_[face_list_tail_[slot_a]] = face_list_head_[slot_b];
      face_list_tail_[slot_a] = face_list_tail_[slot_b];
    }
    kill_edge(edge_id);

    // Rename a and b to the new node; two edges to a common neighbour become one. The merged
    // list is a's kept links, then b's, in their order.
    std::uint32_t head = kNone;
    std::uint32_t* tail = &head;
    for (std::uint32_t old : {a, b}) {
      const std::uint32_t slot = old == a ? slot_a : slot_b;
      for (std::uint32_t link = first_link_[slot], next; link != kNone; link = next) {
        next = next_link_[link];
        const std::uint32_t id = link / 2;
        LiveEdge& e = edges_[id];
        if (!e.alive()) continue;
        std::uint32_t& marker = marker_[slot_of_node_[other_end(e, old)]];
        if (marker == kNone) {
          marker = id;
          (e.a == old ? e.a : e.b) = node;
          *tail = link;
          tail = &next_link_[link];
        } else {
          combine_shared_edges(marker, id);
          edges_[marker].raise_cost_bound(e.cost_bound);
          kill_edge(id);
        }
      }
    }
    *tail = kNone;
    first_link_[slot_a] = head;
    first_link_[slot_b] = kNone;
    for (std::uint32_t link = head; link != kNone; link = next_link_[link])
      marker_[slot_of_node_[other_end(edges_[link / 2], node)]] = kNone;

    for (std::uint32_t link = head; link != kNone; link = next_link_[link]) {
      const std::uint32_t id = link / 2;
      const LiveEdge& e = edges_[id];
      // A zero bound would reach the top before the next merge anyway: evaluate it now.
      const double bound = lazy_ ? queued_bound(e) : 0;
      if (bound > 0)
        heap_.push_back(
            {bound, false, PrimitiveType::Plane, merged_degree(e.a, e.b), e.a, e.b, id});
      else
        heap_.push_back(candidate(id));
      std::push_heap(heap_.begin(), heap_.end(), comes_after);
    }
    compact_heap_if_stale();
  }

  // Re-evaluated candidates leave their old entries behind; drop them once they outnumber the
  // live ones. The pop order does not change: live entries have distinct keys.
  void compact_heap_if_stale() {
    if (heap_.size() <= heap_capacity(live_edges_)) return;
    std::erase_if(heap_,
                  [&](const HeapEntry& entry) { return !edges_[entry.edge].is_current(entry); });
    std::make_heap(heap_.begin(), heap_.end(), comes_after);
  }

  static std::size_t heap_capacity(std::size_t live_edges) {
    return live_edges + live_edges / 4 + 1024;
  }

  // What only the merge loop needs (about two thirds of the peak memory) is freed before the
  // caller goes on with the tree.
  void release_working_memory() {
    auto release = [](auto& vector) { std::decay_t<decltype(vector)>().swap(vector); };
    release(stats_);
    release(stats_index_of_slot_);
    release(free_stats_);
    release(slot_of_node_);
    release(face_count_of_slot_);
    release(min_face_of_slot_);
    release(first_link_);
    release(next_link_);
    release(edges_);
    release(combined_shared_);
    release(free_combined_shared_);
    release(heap_);
    release(stamp_);
    release(marker_);
    release(next_face_);
    release(face_list_head_);
    release(face_list_tail_);
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
  std::vector<ClusterStats> stats_;  // merged clusters' statistics, pooled
  // Per slot: an index into stats_, kNone for a single face, kPairTag | dual edge id for a pair.
  std::vector<std::uint32_t> stats_index_of_slot_;
  std::uint32_t newest_pair_key_ = kNone;  // see store_pair()
  ClusterStats newest_pair_;
  std::vector<std::uint32_t> free_stats_;  // unused entries of stats_
  std::vector<std::uint32_t> slot_of_node_;
  std::vector<std::uint32_t> face_count_of_slot_;
  std::vector<std::uint32_t> min_face_of_slot_;
  // Adjacency as intrusive lists: link 2 id + side is edge id on the list of the slot of its
  // a (side 0) or b (side 1) cluster. Dead edges are unlinked lazily.
  std::vector<std::uint32_t> first_link_;  // per slot: first link, kNone if empty
  std::vector<std::uint32_t> next_link_;   // per link
  std::vector<LiveEdge> edges_;
  std::vector<EdgeStats> combined_shared_;  // see LiveEdge::combined_shared
  std::vector<std::uint32_t> free_combined_shared_;
  std::vector<HeapEntry> heap_;
  std::vector<Merge> merges_;
  std::vector<std::uint32_t> stamp_;  // per slot
  std::uint32_t current_stamp_ = 0;
  std::vector<std::uint32_t> marker_;                                       // per slot
  std::vector<std::uint32_t> next_face_, face_list_head_, face_list_tail_;  // exact_costs only
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
