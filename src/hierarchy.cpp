#include "primseg/hierarchy.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "indexed_heap.hpp"
#include "model_selection.hpp"
#include "parallel.hpp"
#include "primseg/error.hpp"

namespace primseg {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kPairTag = 1u << 31;

// A candidate merge in the queue: the dual edge's id and its key. Candidates are ordered by
// (cost, exactness, primitive type, merged degree, smaller node id, larger node id). On equal cost
// simpler types go first, so flat regions are whole before exact curved fits can reach into them.
//
// Lazy evaluation queues candidates whose cost is only a lower bound of theirs (exact = false). At
// equal cost a bound comes before every exact entry, so when an exact entry reaches the top every
// bound left is strictly above it: it is the same minimum the eager scheme finds.
//
// The merged degree is part of the key only at cost zero, where the exact fits of flat and
// exactly curved regions tie in large numbers: it is taken when the candidate is evaluated. Above
// zero the degree is 0 in the key, and exact ties among the cheapest candidates (rare) are settled
// by their current degrees when they reach the top (see step()).
struct QueuedCandidate {
  static constexpr std::uint32_t kMaxDegree = (1u << 28) - 1;

  double cost;
  // exact (bit 31), primitive type (bits 28 to 30), merged degree (bits 0 to 27, saturated at
  // kMaxDegree: a cluster with 2^28 neighbours is beyond any mesh this ranks), so that comparing
  // ranks compares (exact, type, degree).
  std::uint32_t rank;
  std::uint32_t id;  // the dual edge

  QueuedCandidate() = default;
  QueuedCandidate(double key_cost, bool is_exact, PrimitiveType type, std::uint32_t edge_id)
      : cost(key_cost),
        rank(std::uint32_t{is_exact} << 31 | static_cast<std::uint32_t>(type) << 28),
        id(edge_id) {}
  bool exact() const { return (rank >> 31) != 0; }
  std::uint32_t degree() const { return rank & kMaxDegree; }
  void set_degree(std::uint32_t merged_degree) {
    rank = (rank & ~kMaxDegree) | std::min(merged_degree, kMaxDegree);
  }
};
static_assert(sizeof(QueuedCandidate) == 16);
static_assert(kPrimitiveTypeCount <= 8);

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
  std::uint32_t low() const { return std::min(a, b); }
  std::uint32_t high() const { return std::max(a, b); }
  void raise_cost_bound(double bound) {
    if (!(bound > cost_bound)) return;
    float rounded = static_cast<float>(std::min<double>(bound, std::numeric_limits<float>::max()));
    if (rounded > bound) rounded = std::nextafter(rounded, 0.0f);
    cost_bound = std::max(cost_bound, rounded);
  }
};
static_assert(sizeof(LiveEdge) == 16);

// The queue's order; node ids break the remaining ties (live candidates have distinct pairs).
struct ComesFirst {
  const std::vector<LiveEdge>* edges;
  bool operator()(const QueuedCandidate& x, const QueuedCandidate& y) const {
    if (x.cost != y.cost) return x.cost < y.cost;
    if (x.rank != y.rank) return x.rank < y.rank;
    const LiveEdge& ex = (*edges)[x.id];
    const LiveEdge& ey = (*edges)[y.id];
    if (ex.low() != ey.low()) return ex.low() < ey.low();
    return ex.high() < ey.high();
  }
};

using CandidateQueue = detail::IndexedHeap<QueuedCandidate, ComesFirst>;

// Statistics of the clusters that are not stored (faces and pairs), recomputed for a candidate:
// kept from one evaluation to the next so that their storage is reused.
struct Scratch {
  ClusterStats clusters[2];
  ClusterStats faces[2];  // of a pair
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
      : mesh_(std::move(mesh)),
        options_(std::move(options)),
        selector_(options_),
        queue_(0, ComesFirst{&edges_}) {
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
    lazy_ = options_.evaluation != CandidateEvaluation::Eager && !options_.exact_costs;
    max_penalty_ = *std::max_element(options_.type_penalty.begin(), options_.type_penalty.end());
    // Every candidate's cost is independent of the others: evaluate them in parallel, then the
    // degrees (which share scratch arrays) in order.
    std::vector<QueuedCandidate> candidates(edges_.size());
    std::vector<Scratch> scratch(threads);
    detail::parallel_for_threads(edges_.size(), threads, [&](std::size_t id, unsigned thread) {
      candidates[id] = evaluate(static_cast<std::uint32_t>(id), scratch[thread]);
    });
    for (QueuedCandidate& c : candidates)
      if (c.cost == 0) c.set_degree(merged_degree(edges_[c.id].a, edges_[c.id].b));
    evaluations_ = candidates.size();
    queue_ = CandidateQueue(static_cast<std::uint32_t>(edges_.size()), ComesFirst{&edges_});
    queue_.assign(std::move(candidates));
    total_merges_ = f - graph_->component_count();
  }

  bool step() {
    while (!queue_.empty()) {
      const QueuedCandidate top = queue_.top();
      if (!top.exact()) {
        // A bound reached the top: evaluate the candidate. (Its cost is above the bound, so
        // never zero: no degree.)
        queue_.update(evaluate(top.id, scratch_));
        ++evaluations_;
        continue;
      }
      merge(top.cost > 0 ? settle_tie(top) : top.id);
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

  // The top is the cheapest candidate, at a positive cost. Candidates of exactly the same cost
  // and type (a connected group of the heap around its top) are ranked by the degree their merge
  // would make now, then by node ids; the winner's edge.
  std::uint32_t settle_tie(const QueuedCandidate& top) {
    auto ties_top = [&](const QueuedCandidate& c) {
      return c.cost == top.cost && c.rank == top.rank;
    };
    // Breadth-first from the top over children that tie it: every tie has only tying ancestors.
    tied_.assign(1, 0);
    for (std::size_t i = 0; i < tied_.size(); ++i) {
      const std::size_t first = CandidateQueue::kArity * tied_[i] + 1;
      const std::size_t end = std::min(first + CandidateQueue::kArity, queue_.size());
      for (std::size_t c = first; c < end; ++c)
        if (ties_top(queue_.at(c))) tied_.push_back(c);
    }
    if (tied_.size() == 1) return top.id;  // the usual case
    std::uint32_t best = top.id, best_degree = merged_degree(edges_[top.id].a, edges_[top.id].b);
    for (std::size_t position : tied_) {
      const std::uint32_t id = queue_.at(position).id;
      if (id == top.id) continue;
      const std::uint32_t degree = merged_degree(edges_[id].a, edges_[id].b);
      const LiveEdge& e = edges_[id];
      const LiveEdge& b = edges_[best];
      if (degree < best_degree ||
          (degree == best_degree && std::pair(e.low(), e.high()) < std::pair(b.low(), b.high()))) {
        best = id;
        best_degree = degree;
      }
    }
    return best;
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
    queue_.erase(id);
  }

  // A live cluster's centred statistics: stored for a merged cluster of three faces or more,
  // computed into `scratch` for a face or a pair of faces, with the moments up to `max_degree`
  // (2 for a candidate only a plane can fit: see ModelSelector::moment_degree()).
  const ClusterStats& stats_of(std::uint32_t node, Scratch& scratch, int part,
                              int max_degree) const {
    const std::uint32_t slot = slot_of_node_[node];
    const std::uint32_t index = stats_index_of_slot_[slot];
    const bool samples = selector_.needs_samples();
    ClusterStats& stats = scratch.clusters[part];
    if (index == kNone) {
      graph_->face_stats(slot, stats, samples, max_degree);
    } else if (index == newest_pair_key_) {
      return newest_pair_;
    } else if (index & kPairTag) {
      // The same union, by the same operations, as when the pair merged.
      const DualEdge& e = graph_->edges()[index & ~kPairTag];
      graph_->face_stats(e.first, scratch.faces[0], samples, max_degree);
      graph_->face_stats(e.second, scratch.faces[1], samples, max_degree);
      stats = ClusterView(scratch.faces[0], scratch.faces[1], e.shared).stats(max_degree);
    } else {
      return stats_[index];
    }
    return stats;
  }

  std::uint32_t triangle_count(std::uint32_t node) const {
    const std::uint32_t slot = slot_of_node_[node];
    const std::uint32_t index = stats_index_of_slot_[slot];
    if (index == kNone) return graph_->first_triangle(slot + 1) - graph_->first_triangle(slot);
    if (index & kPairTag) {
      const DualEdge& e = graph_->edges()[index & ~kPairTag];
      return graph_->first_triangle(e.first + 1) - graph_->first_triangle(e.first) +
             graph_->first_triangle(e.second + 1) - graph_->first_triangle(e.second);
    }
    return stats_[index].triangle_count;
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

  detail::SelectedModel select(const ClusterView& cluster, const LiveEdge& e) const {
    if (!options_.exact_costs) return selector_.select(cluster);
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
    return selector_.select(cluster, &exact);
  }

  // A candidate's queue entry, without its degree. Reads shared state and writes only this
  // edge's bound (safe in parallel over distinct edges).
  QueuedCandidate evaluate(std::uint32_t id, Scratch& scratch) {
    LiveEdge& e = edges_[id];
    const int degree = selector_.moment_degree(triangle_count(e.a) + triangle_count(e.b));
    const ClusterView cluster(stats_of(e.a, scratch, 0, degree), stats_of(e.b, scratch, 1, degree),
                              shared_edges(id));
    const detail::SelectedModel model = select(cluster, e);
    if (lazy_) e.raise_cost_bound(model.superset_cost_bound);
    return {model.cost, true, model.fit.primitive.type, id};
  }

  // The edge's cost bound if it holds for the current union, else 0. A cost that would snap to
  // zero (at most zero_cost_tolerance × the union's spread, for the cheapest type) can be below
  // any bound from a subset, so the bound holds only above that level. The union's spread is
  // exact from the parts' (Σ w |x − c|² adds a w_a w_b / (w_a + w_b) |c_a − c_b|² term); the
  // factor 2 covers round-off.
  double queued_bound(const LiveEdge& e) {
    if (!(e.cost_bound > 0)) return 0;
    const Moments& a = stats_of(e.a, scratch_, 0, 2).moments;
    const Moments& b = stats_of(e.b, scratch_, 1, 2).moments;
    const double wa = a.weight(), wb = b.weight();
    if (!(wa > 0) || !(wb > 0)) return 0;
    const double spread = a.second_moment().trace() + b.second_moment().trace() +
                          wa * wb / (wa + wb) * (a.origin() - b.origin()).squaredNorm();
    return e.cost_bound > 2 * max_penalty_ * options_.zero_cost_tolerance * spread ? e.cost_bound
                                                                                   : 0.0;
  }

  void merge(std::uint32_t edge_id) {
    LiveEdge& edge = edges_[edge_id];
    const std::uint32_t a = edge.a, b = edge.b;
    const std::uint32_t slot_a = slot_of_node_[a], slot_b = slot_of_node_[b];
    const ClusterView cluster(stats_of(a, scratch_, 0, 4), stats_of(b, scratch_, 1, 4),
                              shared_edges(edge_id));
    const detail::SelectedModel model = select(cluster, edge);
    ClusterStats merged = cluster.stats();
    const std::uint32_t node = next_node();

    Merge record;
    record.first = std::min(a, b);
    record.second = std::max(a, b);
    record.cost = model.cost;
    record.error = model.fit.error;
    record.weight = cluster.weight();
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
      if (bound > 0) {
        queue_.update({bound, false, PrimitiveType::Plane, id});
        continue;
      }
      QueuedCandidate candidate = evaluate(id, scratch_);
      ++evaluations_;
      if (candidate.cost == 0) candidate.set_degree(merged_degree(e.a, e.b));
      queue_.update(candidate);
    }
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
    queue_.clear();
    release(stamp_);
    release(marker_);
    release(tied_);
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
    double weight = stats_of(joined, scratch_, 0, 2).moments.weight();
    std::uint32_t faces = face_count_of_slot_[slot_of_node_[joined]];
    for (std::size_t i = 1; i < roots.size(); ++i) {
      const std::uint32_t other = roots[i].second;
      Merge record;
      record.first = std::min(joined, other);
      record.second = std::max(joined, other);
      record.cost = cost;
      record.weight = weight += stats_of(other, scratch_, 0, 2).moments.weight();
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
  std::vector<Merge> merges_;
  std::vector<std::uint32_t> stamp_;  // per slot
  std::uint32_t current_stamp_ = 0;
  std::vector<std::uint32_t> marker_;                                       // per slot
  std::vector<std::size_t> tied_;  // settle_tie()'s queue positions
  Scratch scratch_;                // the merge loop's
  CandidateQueue queue_;  // after edges_, which its order reads
  std::vector<std::uint32_t> next_face_, face_list_head_, face_list_tail_;  // exact_costs only
  std::uint32_t total_merges_ = 0;
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
