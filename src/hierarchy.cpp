#include "primseg/hierarchy.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <type_traits>
#include <utility>

#include "batch_pool.hpp"
#include "evaluation_tape.hpp"
#include "hierarchy_regions.hpp"
#include "huge_pages.hpp"
#include "indexed_heap.hpp"
#include "model_selection.hpp"
#include "no_index.hpp"
#include "page_warmer.hpp"
#include "parallel.hpp"
#include "primseg/error.hpp"
#include "tree_check.hpp"

namespace primseg {
namespace {

using detail::kNone;
constexpr std::uint32_t kPairTag = 1u << 31;
// Candidates evaluated at once from which they are shared among the threads even when each is
// cheap (see parallel_from_).
constexpr std::size_t kParallelBatch = 32;
// Lazy evaluation: a new candidate waits in the queue under its bound only if the bound is at
// least this many times the queue's top key. Nearer bounds mostly reach the top anyway (83% of
// those within twice the top on bunny00 with planes, 48% between two and four times, 25% between
// four and eight), and then are evaluated cold, from data that has left the caches, and re-keyed
// in the heap: they are cheaper to evaluate at once, like the eager order does. Either way the
// candidate's cost is the same, and so is the tree.
constexpr double kDeferFactor = 2;

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
  PrimitiveType type() const { return static_cast<PrimitiveType>((rank >> 28) & 7); }
  std::uint32_t degree() const { return rank & kMaxDegree; }
  void set_degree(std::uint32_t merged_degree) {
    rank = (rank & ~kMaxDegree) | std::min(merged_degree, kMaxDegree);
  }
};
static_assert(sizeof(QueuedCandidate) == 16);
static_assert(kPrimitiveTypeCount <= 8);

// 16 bytes: the builder keeps one per dual edge.
struct LiveEdge {
  std::uint32_t a,
      b;  // slots of the two clusters (see HierarchyBuilder::Impl); a = kNone once dead
  // The mesh edges between the two clusters are those of the input dual edge with this id until
  // two edges to a common neighbour are combined; then their sum lives in a pool at this index.
  std::uint32_t combined_shared = kNone;
  // A lower bound of the cost of merging any two clusters that contain a and b (lazy only),
  // rounded down to a float: a looser bound costs an evaluation, never a different tree.
  float cost_bound = 0;

  bool alive() const { return a != kNone; }
  void raise_cost_bound(double bound) {
    if (!(bound > cost_bound)) return;
    float rounded = static_cast<float>(std::min<double>(bound, std::numeric_limits<float>::max()));
    if (rounded > bound) rounded = std::nextafter(rounded, 0.0f);
    cost_bound = std::max(cost_bound, rounded);
  }
};
static_assert(sizeof(LiveEdge) == 16);

// The (smaller, larger) node ids of an edge's clusters when it was queued: the queue's last key.
using NodePair = std::array<std::uint32_t, 2>;

// The queue's order. The node ids settle the remaining ties (live candidates have distinct
// pairs), as they were when the candidate was queued: kept per edge, out of the 16-byte node.
struct ComesFirst {
  const std::vector<NodePair>* queued_pairs;
  bool operator()(const QueuedCandidate& x, const QueuedCandidate& y) const {
    if (x.cost != y.cost) return x.cost < y.cost;
    if (x.rank != y.rank) return x.rank < y.rank;
    return (*queued_pairs)[x.id] < (*queued_pairs)[y.id];
  }
};

using CandidateQueue = detail::IndexedHeap<QueuedCandidate, ComesFirst>;

// What the builder keeps of a slot: a live cluster lives in the slot of one of its input faces
// (that face's id). Two slots share a cache line, and a candidate's evaluation reads its two
// clusters' slots only.
struct Slot {
  std::uint32_t node;   // the cluster's node id; kNone once merged into another slot
  std::uint32_t stats;  // index into the pool of statistics; kNone: a face; kPairTag | edge: a pair
  std::uint32_t faces;  // input faces in the cluster
  std::uint32_t triangles;   // triangles in the cluster
  std::uint32_t min_face;    // its lowest input face (orders the trailing merges)
  std::uint32_t first_link;  // head of its adjacency list; kNone if empty
  std::uint32_t marker;      // merge(): the kept edge to this neighbour, else kNone
  std::uint32_t stamp;       // merged_degree(): the last count this neighbour was counted in
};
static_assert(sizeof(Slot) == 32);

// Statistics of the clusters that are not stored (faces and pairs), recomputed for a candidate:
// kept from one evaluation to the next so that their storage is reused.
struct Scratch {
  ClusterStats clusters[2];
  ClusterStats faces[2];                            // of a pair
  FaceCorners cluster_corners[2], face_corners[2];  // the same for faces by their corners

  // Recently read faces by face id, direct-mapped: the first evaluation reads a face once per
  // edge, with its edges to higher faces in a row, and a face next to a growing cluster is read
  // again at each of the cluster's merges. An entry holds the face's corners, or its statistics
  // (with moments up to cached_degree) when it has too many triangles or samples are needed.
  static constexpr std::uint32_t kCachedFaces = 64;
  std::array<std::uint32_t, kCachedFaces> cached_face;
  std::array<bool, kCachedFaces> cached_by_corners;
  std::array<int, kCachedFaces> cached_degree;
  std::array<FaceCorners, kCachedFaces> cached_corners;
  std::array<ClusterStats, kCachedFaces> cached_stats;
  // Entries an evaluation is still reading, not to be evicted (kNone: none).
  std::array<std::uint32_t, 2> pinned;

  Scratch() { cached_face.fill(kNone); }
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Hierarchy

Hierarchy::Hierarchy(std::shared_ptr<const Mesh> mesh, HierarchyOptions options,
                     std::vector<Merge> merges)
    : Hierarchy(std::move(mesh), std::move(options), std::move(merges), nullptr) {
  detail::check_tree_parts(*graph_, options_, merges_);
}

Hierarchy::Hierarchy(std::shared_ptr<const Mesh> mesh, HierarchyOptions options,
                     std::vector<Merge> merges, std::unique_ptr<DualGraph> graph)
    : mesh_(std::move(mesh)),
      options_(std::move(options)),
      graph_(std::move(graph)),
      merges_(std::move(merges)) {
  // The leaves' rule, which also validates the options.
  leaf_selector_ = std::make_shared<const detail::ModelSelector>(options_);
  if (!mesh_ || mesh_->face_count() == 0) throw InvalidInputError("mesh has no faces");
  const std::uint32_t f = mesh_->face_count();
  if (merges_.size() != f - 1)
    throw InvalidInputError("a hierarchy of " + std::to_string(f) + " faces needs " +
                            std::to_string(f - 1) + " merges, not " +
                            std::to_string(merges_.size()));
  if (!graph_) graph_ = std::make_unique<DualGraph>(*mesh_, options_.weights, options_.threads);
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
detail::SelectedModel select_leaf(const detail::ModelSelector& selector, const DualGraph& graph,
                                  std::uint32_t face) {
  return selector.select(graph.face_stats(face, selector.needs_samples()).centred());
}

}  // namespace

void Hierarchy::check_node(std::uint32_t node) const {
  if (node >= node_count())
    throw InvalidInputError(std::to_string(node) + " is not a node of the tree (" +
                            std::to_string(node_count()) + " nodes: 2F − 1)");
}

Primitive Hierarchy::primitive(std::uint32_t node) const {
  check_node(node);
  if (!is_leaf(node)) return merges_[node - face_count()].primitive;
  return graph_->frame().to_input(select_leaf(*leaf_selector_, *graph_, node).fit.primitive);
}

double Hierarchy::error(std::uint32_t node) const {
  check_node(node);
  if (!is_leaf(node)) return merges_[node - face_count()].error;
  return select_leaf(*leaf_selector_, *graph_, node).fit.error;
}

double Hierarchy::weight(std::uint32_t node) const {
  check_node(node);
  if (!is_leaf(node)) return merges_[node - face_count()].weight;
  return graph_->face_stats(node, false, 2).moments.weight();  // (the weight is of degree 0)
}

std::uint32_t Hierarchy::face_count(std::uint32_t node) const {
  check_node(node);
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

namespace {

// Whether the merge loop runs on the graph in spatial order (see FaceOrder). Not with the torus:
// faces' samples would take other priorities.
bool merges_in_spatial_order(FaceOrder order, const detail::ModelSelector& selector,
                             const DualGraph& graph) {
  if (selector.needs_samples()) return false;
  if (order != FaceOrder::Automatic) return order == FaceOrder::Spatial;
  constexpr std::uint32_t kFrom = std::uint32_t{1} << 17, kWindow = 1024;
  if (graph.face_count() < kFrom) return false;
  const std::size_t near = static_cast<std::size_t>(
      std::count_if(graph.edges().begin(), graph.edges().end(),
                    [](const DualEdge& e) { return e.second - e.first < kWindow; }));
  return 2 * near < graph.edges().size();
}

}  // namespace

class HierarchyBuilder::Impl {
 public:
  Impl(std::shared_ptr<const Mesh> mesh, HierarchyOptions options)
      : mesh_(std::move(mesh)),
        options_(std::move(options)),
        selector_(options_),
        pool_(detail::thread_count(options_.threads)),
        scratch_(pool_.thread_count()),
        queue_(0, ComesFirst{&queued_pairs_}) {
    if (!mesh_) throw InvalidInputError("no mesh");
    mesh_->validate();
    check_geometric_range(*mesh_);
    if (detail::evaluation_tape.mode != detail::EvaluationTape::Mode::Off) {
      if (pool_.thread_count() != 1 || options_.regions > 1)
        throw Error("an evaluation tape needs one thread and no regions");
      tape_ = &detail::evaluation_tape;
    }
    // With regions, the tree's first merges are theirs, and the whole mesh's graph is made by
    // the thread that finishes its region first.
    const std::uint32_t f = mesh_->face_count();
    detail::reserve_huge(merges_, f - 1);
    if (options_.regions > 1)
      evaluations_ = detail::region_merges(*mesh_, options_, merges_, [this] {
        graph_ = std::make_unique<DualGraph>(*mesh_, options_.weights, 1);
      });
    if (!graph_) graph_ = std::make_unique<DualGraph>(*mesh_, options_.weights, options_.threads);
    // Where a region chained a non-manifold edge's triangles otherwise than the whole mesh, the
    // regions' merges are no tree of this graph: the exact order then, from the faces.
    if (!merges_.empty() && !detail::merges_join_linked_clusters(*graph_, merges_)) merges_.clear();
    // The loop may run on the graph in a spatial order. Node ids stay the input's faces, so the
    // queue's ties are the input's, and so are each dual edge's sides, so every union is summed
    // in the input's order: the tree is the same, bit for bit. (From the regions' clusters, as
    // listed: start_from() keeps each cluster in the slot of its lowest input face.)
    if (merges_.empty() && merges_in_spatial_order(options_.face_order, selector_, *graph_)) {
      SpatialOrder order = graph_->in_spatial_order();
      graph_ = std::move(order.graph);
      original_face_ = std::move(order.original_face);
    }
    // Statistics are stored for clusters of three faces or more only (at most F / 3 live at
    // once); a single face's or a pair's are recomputed when needed (see store_pair()).
    detail::reserve_huge(stats_, f / 3 + 1);  // address space: touched as clusters form
    detail::resize_huge(slots_, f);
    detail::resize_huge(pair_cache_, kCachedPairs);  // (half a megabyte: its pages at once)
    for (std::uint32_t face = 0; face < f; ++face)
      slots_[face] = {input_face(face),
                      kNone,
                      1,
                      graph_->first_triangle(face + 1) - graph_->first_triangle(face),
                      input_face(face),
                      kNone,
                      kNone,
                      0};
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
    detail::reserve_huge_to_fill(edges_, dual_edges.size());
    for (const DualEdge& e : dual_edges) edges_.push_back({e.first, e.second});
    // Each face's list in increasing edge id: prepend in decreasing order. (The lists' order
    // changes no sum and no tie: a graph in spatial order gives the same tree.)
    detail::resize_huge(next_link_, 2 * dual_edges.size());
    for (std::size_t id = dual_edges.size(); id-- > 0;)
      for (std::uint32_t side = 0; side < 2; ++side) {
        const std::uint32_t face = side == 0 ? dual_edges[id].first : dual_edges[id].second;
        const auto link = static_cast<std::uint32_t>(2 * id + side);
        next_link_[link] = slots_[face].first_link;
        slots_[face].first_link = link;
      }
    batched_ = options_.merge_batch_tolerance > 0;
    // Batches keep stale costs instead of bounds: no bound is ever queued there.
    lazy_ = options_.evaluation != CandidateEvaluation::Eager && !options_.exact_costs && !batched_;
    if (batched_) {
      formed_at_.assign(f, 0);
      evaluated_at_.assign(dual_edges.size(), 0);
    }
    by_corners_ = !selector_.needs_samples();
    // A merge's own jobs are shared only when its fits are costly; cheap ones only in numbers (a
    // batch of merge_batch_tolerance): on two cores that share no cache, sharing a merge's five or
    // so made the build 30% slower than one thread (docs/method.md, "Threads in the merge loop").
    parallel_from_ = options_.exact_costs || !selector_.closed_form() ? 2 : kParallelBatch;
    max_penalty_ = *std::max_element(options_.type_penalty.begin(), options_.type_penalty.end());
    if (!merges_.empty()) start_from();
    // Every candidate's cost and first degree is independent of the others: all in parallel.
    // In chunks of consecutive edges: those of a face to its higher neighbours follow each other,
    // and the face's statistics stay in the thread's cache.
    std::vector<QueuedCandidate> candidates;
    detail::resize_huge(candidates, edges_.size());
    constexpr std::size_t kChunk = 256;
    auto first_evaluation = [&](std::size_t chunk, unsigned thread) {
      const std::size_t end = std::min(edges_.size(), (chunk + 1) * kChunk);
      for (std::size_t id = chunk * kChunk; id < end; ++id) {
        QueuedCandidate& c = candidates[id];
        if (!edges_[id].alive()) {
          c.id = kNone;  // inside a region's cluster, or combined with another edge
          continue;
        }
        c = evaluate(static_cast<std::uint32_t>(id), scratch_[thread]);
        if (c.cost == 0) c.set_degree(first_merged_degree(edges_[id].a, edges_[id].b));
      }
    };
    pool_.run((edges_.size() + kChunk - 1) / kChunk, first_evaluation);
    detail::resize_huge(queued_pairs_, edges_.size());
    if (merges_.empty()) {
      for (std::size_t id = 0; id < edges_.size(); ++id)
        queued_pairs_[id] = {input_face(dual_edges[id].first),
                             input_face(dual_edges[id].second)};  // first < second in the input
    } else {
      std::erase_if(candidates, [](const QueuedCandidate& c) { return c.id == kNone; });
      for (const QueuedCandidate& c : candidates) queued_pairs_[c.id] = node_pair(edges_[c.id]);
    }
    evaluations_ += candidates.size();
    queue_ = CandidateQueue(static_cast<std::uint32_t>(edges_.size()), ComesFirst{&queued_pairs_});
    queue_.assign(candidates);
    total_merges_ = f - graph_->component_count();
    // The loop is the first to write the merge records and the statistics pool; with a second
    // thread allowed, their pages are faulted in ahead of it (see page_warmer.hpp). Else the
    // records, which will all be written, are faulted in now, at half the cost of a fault each.
    if (pool_.thread_count() >= 2 && merges_.capacity() * sizeof(Merge) >= kWarmFrom)
      warmer_.start({{merges_.data(), merges_.capacity() * sizeof(Merge), &merges_used_},
                     {stats_.data(), stats_.capacity() * sizeof(ClusterStats), &stats_used_}},
                    kWarmLead);
    else
      detail::populate_pages(merges_.data(), merges_.capacity() * sizeof(Merge));
  }

  // Starts from the clusters the regions' merges made (HierarchyOptions::regions): each lives in
  // the slot of its lowest face, its statistics summed from its faces', its edges to each
  // neighbour combined into one, the mesh edges between them summed in edge order. The merges
  // are the tree's first, with weights summed as the whole mesh weighs its faces.
  void start_from() {
    std::vector<Merge>& prefix = merges_;
    const auto f = static_cast<std::uint32_t>(slots_.size());
    // (The arrays sized by faces ask for huge pages and are faulted in at once: a first touch
    // of each 4 KB page costs more than filling it.)
    std::vector<std::uint32_t> slot_of_node, parent, cluster;
    std::vector<double> weight;
    detail::resize_huge(slot_of_node, f + prefix.size());
    detail::resize_huge(parent, f);
    detail::resize_huge(cluster, f);
    detail::resize_huge(weight, f + prefix.size());
    std::iota(slot_of_node.begin(), slot_of_node.begin() + f, 0u);
    std::iota(parent.begin(), parent.end(), 0u);
    detail::parallel_for(f, pool_.thread_count(), [&](std::size_t face) {
      for (std::uint32_t t = graph_->first_triangle(static_cast<std::uint32_t>(face));
           t < graph_->first_triangle(static_cast<std::uint32_t>(face) + 1); ++t)
        for (const double w : graph_->corner_weights(t)) weight[face] += w;
    });
    for (std::uint32_t i = 0; i < prefix.size(); ++i) {
      Merge& m = prefix[i];
      const std::uint32_t a = slot_of_node[m.first], b = slot_of_node[m.second];
      const std::uint32_t kept = std::min(a, b), gone = std::max(a, b);
      parent[gone] = kept;
      slot_of_node[f + i] = kept;
      m.weight = weight[f + i] = weight[m.first] + weight[m.second];
      Slot& slot = slots_[kept];
      slot.node = f + i;
      slot.faces = m.face_count;
      slot.triangles += slots_[gone].triangles;
      slot.min_face = kept;
      slots_[gone].node = kNone;
      max_cost_ = std::max(max_cost_, m.cost);
    }
    for (std::uint32_t face = 0; face < f; ++face) {
      std::uint32_t root = face;
      while (parent[root] != root) root = parent[root];
      cluster[face] = root;
      for (std::uint32_t x = face; parent[x] != root;) x = std::exchange(parent[x], root);
    }

    // Edges inside a cluster die (their mesh edges go to its statistics); the first edge between
    // two clusters is kept, the others' mesh edges are added to it.
    std::vector<std::uint32_t> merged, merged_index;  // clusters of two faces or more
    detail::resize_huge(merged_index, f);
    for (std::uint32_t slot = 0; slot < f; ++slot)
      if (slots_[slot].node != kNone && slots_[slot].faces >= 2) {
        merged_index[slot] = static_cast<std::uint32_t>(merged.size());
        merged.push_back(slot);
      } else {
        merged_index[slot] = kNone;
      }
    const std::vector<DualEdge>& dual_edges = graph_->edges();
    std::vector<EdgeStats> inside(merged.size());
    std::vector<std::uint32_t> pair_edge(merged.size(), kNone);
    std::vector<std::array<std::uint32_t, 3>> between;  // (lower slot, higher slot, edge)
    detail::reserve_huge(between, dual_edges.size());
    for (std::uint32_t id = 0; id < dual_edges.size(); ++id) {
      const std::uint32_t a = cluster[dual_edges[id].first], b = cluster[dual_edges[id].second];
      edges_[id] = {a, b};
      if (a == b) {
        inside[merged_index[a]] += dual_edges[id].shared;
        pair_edge[merged_index[a]] = id;
        edges_[id].a = edges_[id].b = kNone;
      } else {
        between.push_back({std::min(a, b), std::max(a, b), id});
      }
    }
    std::sort(between.begin(), between.end());
    for (std::size_t i = 1, kept = 0; i < between.size(); ++i) {
      if (between[i][0] != between[kept][0] || between[i][1] != between[kept][1]) {
        kept = i;
        continue;
      }
      combine_shared_edges(between[kept][2], between[i][2]);
      edges_[between[i][2]].a = edges_[between[i][2]].b = kNone;
    }
    for (Slot& slot : slots_) slot.first_link = kNone;
    for (std::size_t id = dual_edges.size(); id-- > 0;)
      if (edges_[id].alive())
        for (std::uint32_t side = 0; side < 2; ++side) {
          const std::uint32_t slot = side == 0 ? edges_[id].a : edges_[id].b;
          const auto link = static_cast<std::uint32_t>(2 * id + side);
          next_link_[link] = slots_[slot].first_link;
          slots_[slot].first_link = link;
        }

    // Statistics of the clusters of two faces or more, from their faces in increasing order.
    std::vector<std::uint32_t> first_face, faces;
    detail::resize_huge(first_face, std::size_t{f} + 1);
    detail::resize_huge(faces, f);
    for (std::uint32_t face = 0; face < f; ++face) ++first_face[cluster[face] + 1];
    std::partial_sum(first_face.begin(), first_face.end(), first_face.begin());
    {
      std::vector<std::uint32_t> fill(first_face.begin(), first_face.end() - 1);
      for (std::uint32_t face = 0; face < f; ++face) faces[fill[cluster[face]]++] = face;
    }
    std::vector<ClusterStats> stats(merged.size());
    const bool samples = selector_.needs_samples();
    const int degree = selector_.stored_moment_degree();
    detail::parallel_for_threads(merged.size(), pool_.thread_count(), [&](std::size_t i, unsigned) {
      const std::uint32_t slot = merged[i];
      graph_->face_stats(faces[first_face[slot]], stats[i], samples, degree);
      FaceCorners corners;
      for (std::uint32_t k = first_face[slot] + 1; k < first_face[slot + 1]; ++k)
        if (by_corners_ && graph_->face_corners(faces[k], corners))
          stats[i].add(corners, degree);
        else
          stats[i].merge(graph_->face_stats(faces[k], samples, degree), EdgeStats{}, degree);
      stats[i].edges += inside[i];
      stats[i] = stats[i].centred(degree);  // as the merge loop stores them
    });
    // Stored clusters have three faces or more, but for those pairs: room for them all, ahead of
    // the page warmer, which reads where the pool is.
    const auto unpaired = static_cast<std::size_t>(
        std::count_if(merged.begin(), merged.end(), [&](std::uint32_t slot) {
          return slots_[slot].faces == 2 && pair_edge[merged_index[slot]] == kNone;
        }));
    detail::reserve_huge(stats_, f / 3 + 1 + unpaired);
    for (std::size_t i = 0; i < merged.size(); ++i) {
      const std::uint32_t slot = merged[i];
      // (A region's pair joined across a non-manifold edge may have no dual edge of the whole
      // mesh between its faces, whose triangles there are chained in another order: it keeps
      // its statistics then, as a larger cluster.)
      if (slots_[slot].faces == 2 && pair_edge[i] != kNone)
        store_pair(slot, pair_edge[i], slots_[slot].triangles, std::move(stats[i]));
      else
        store_stats(slot, std::move(stats[i]));
    }
    merges_used_.store(merges_.size() * sizeof(Merge), std::memory_order_relaxed);
  }

  bool step() {
    if (batched_) return batched_step();
    while (!queue_.empty()) {
      const QueuedCandidate top = queue_.top();
      if (!top.exact()) {
        // A bound reached the top: evaluate the candidate. (Its cost is above the bound, so
        // never zero: no degree.)
        // A bound runner-up is most often the next one evaluated here, cold: its edge is asked
        // for now, its clusters' first reads once the edge has arrived. (An exact runner-up is the
        // next merge's, which asks for its own.)
        const std::uint32_t p = queue_.runner_up();
        const std::uint32_t next =
            p != CandidateQueue::kAbsent && !queue_.at(p).exact() ? queue_.at(p).id : kNone;
        if (next != kNone) __builtin_prefetch(&edges_[next]);
        const QueuedCandidate evaluated = evaluate(top.id, scratch_[0]);
        if (next != kNone) {
          const LiveEdge& e = edges_[next];
          prefetch_candidate(next, e.a);
          prefetch_cluster(e.b);
        }
        queue_.update(evaluated);
        ++evaluations_;
        continue;
      }
      merge(top.cost > 0 ? settle_tie(top) : top);
      return true;
    }
    return false;
  }

  std::uint32_t merge_count() const { return static_cast<std::uint32_t>(merges_.size()); }
  std::uint32_t total_merge_count() const { return total_merges_; }
  std::uint64_t evaluation_count() const { return evaluations_; }
  std::span<const Merge> merges() const { return merges_; }
  std::vector<Merge> take_merges() {
    if (!graph_) throw Error("HierarchyBuilder::finish() was already called");
    warmer_.stop();  // (it reads the records' counter)
    return std::move(merges_);
  }

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
    // A graph in spatial order is not the tree's: Hierarchy builds the input's.
    if (!original_face_.empty()) {
      graph_.reset();
      std::vector<std::uint32_t>().swap(original_face_);
    }
    return {std::move(mesh_), std::move(options_), std::move(merges_), std::move(graph_)};
  }

 private:
  // The input face (and leaf node) that face `face` of graph_ is.
  std::uint32_t input_face(std::uint32_t face) const {
    return original_face_.empty() ? face : original_face_[face];
  }

  std::uint32_t next_node() const {
    return mesh_->face_count() + static_cast<std::uint32_t>(merges_.size());
  }

  // Queues a candidate of the new cluster with its current node ids. (Set just before: the
  // queue's order reads them for the candidate's old entry until it is replaced.)
  void requeue(const QueuedCandidate& candidate) {
    queued_pairs_[candidate.id] = node_pair(edges_[candidate.id]);
    queue_.update(candidate);
  }

  NodePair node_pair(const LiveEdge& e) const {
    const std::uint32_t a = slots_[e.a].node, b = slots_[e.b].node;
    return {std::min(a, b), std::max(a, b)};
  }

  static std::uint32_t other_end(const LiveEdge& e, std::uint32_t slot) {
    return e.a == slot ? e.b : e.a;
  }

  // Number of clusters adjacent to the union of the clusters in slots a and b; unlinks dead
  // edges from the two lists on the way.
  std::uint32_t merged_degree(std::uint32_t a, std::uint32_t b) {
    ++current_stamp_;
    std::uint32_t degree = 0;
    for (std::uint32_t slot : {a, b}) {
      std::uint32_t* link = &slots_[slot].first_link;
      while (*link != kNone) {
        const LiveEdge& e = edges_[*link / 2];
        if (!e.alive()) {
          *link = next_link_[*link];
          continue;
        }
        link = &next_link_[*link];
        const std::uint32_t other = other_end(e, slot);
        if (other == a || other == b) continue;
        std::uint32_t& stamp = slots_[other].stamp;
        if (stamp == current_stamp_) continue;
        stamp = current_stamp_;
        ++degree;
      }
    }
    return degree;
  }

  // merged_degree() before any merge, writing nothing (safe on several threads): faces have few
  // neighbours, counted distinct by a linear search of those seen.
  std::uint32_t first_merged_degree(std::uint32_t a, std::uint32_t b) const {
    std::array<std::uint32_t, 32> inline_seen;
    std::vector<std::uint32_t> many_seen;
    std::uint32_t count = 0;
    for (std::uint32_t slot : {a, b})
      for (std::uint32_t link = slots_[slot].first_link; link != kNone; link = next_link_[link]) {
        const std::uint32_t other = other_end(edges_[link / 2], slot);
        if (other == a || other == b) continue;
        if (count < inline_seen.size()) {
          if (std::find(inline_seen.begin(), inline_seen.begin() + count, other) ==
              inline_seen.begin() + count)
            inline_seen[count++] = other;
        } else {
          many_seen.push_back(other);  // sorted out below
        }
      }
    if (many_seen.empty()) return count;
    many_seen.insert(many_seen.end(), inline_seen.begin(), inline_seen.end());
    std::sort(many_seen.begin(), many_seen.end());
    return static_cast<std::uint32_t>(std::unique(many_seen.begin(), many_seen.end()) -
                                      many_seen.begin());
  }

  // The top is the cheapest candidate, at a positive cost. Candidates of exactly the same cost
  // and type (a connected group of the heap around its top) are ranked by the degree their merge
  // would make now, then by node ids; the winner.
  QueuedCandidate settle_tie(const QueuedCandidate& top) {
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
    if (tied_.size() == 1) return top;  // the usual case
    QueuedCandidate best = top;
    std::uint32_t best_degree = merged_degree(edges_[top.id].a, edges_[top.id].b);
    for (std::size_t position : tied_) {
      const QueuedCandidate& candidate = queue_.at(position);
      if (candidate.id == top.id) continue;
      const std::uint32_t degree = merged_degree(edges_[candidate.id].a, edges_[candidate.id].b);
      if (degree < best_degree ||
          (degree == best_degree && queued_pairs_[candidate.id] < queued_pairs_[best.id])) {
        best = candidate;
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
    queue_.erase(id);
    LiveEdge& e = edges_[id];
    if (e.combined_shared != kNone) free_combined_shared_.push_back(e.combined_shared);
    e.combined_shared = kNone;
    e.a = e.b = kNone;
  }

  // A live cluster as a part of a union: its centred statistics, stored for a merged cluster of
  // three faces or more, computed into `scratch` for a pair of faces (with the moments up to
  // `max_degree`: 2 for a candidate only a plane can fit, see ModelSelector::moment_degree()); a
  // single face by its corners (or its statistics: see face_part()).
  // Part 0 of a union must be read before part 1: it stays in place while part 1 is read.
  ClusterPart part_of(std::uint32_t slot, Scratch& scratch, int part, int max_degree) const {
    if (part == 0) scratch.pinned.fill(kNone);
    const std::uint32_t index = slots_[slot].stats;
    if (index == kNone)
      return face_part(slot, max_degree, scratch, part, scratch.clusters[part],
                       scratch.cluster_corners[part]);
    if (index & kPairTag) {
      const bool by_corners = pair_by_corners(slots_[slot].triangles);
      if (!by_corners) {
        const CachedPair& cached = pair_cache_[index % kCachedPairs];
        if (cached.key == index) return cached.stats;
      }
      // The same union, by the same operations, as when the pair merged.
      const DualEdge& e = graph_->edges()[index & ~kPairTag];
      const std::array<std::uint32_t, 2> pinned = scratch.pinned;
      const ClusterPart first =
          face_part(e.first, max_degree, scratch, 1, scratch.faces[0], scratch.face_corners[0]);
      const ClusterPart second =
          face_part(e.second, max_degree, scratch, 1, scratch.faces[1], scratch.face_corners[1]);
      if (by_corners) {
        FaceCorners::unite(*first.face(), *second.face(), e.shared, scratch.cluster_corners[part]);
        scratch.pinned = pinned;
        return scratch.cluster_corners[part];
      }
      ClusterStats& stats = scratch.clusters[part];
      stats = ClusterView(first, second, e.shared).stats(max_degree);
      scratch.pinned = pinned;
      return stats;
    }
    return stats_[index];
  }

  // A face from the scratch's cache, read into a fallback instead when its entry is pinned; pins
  // the entry used in pinned[pin]. By its corners unless it has too many triangles or a type
  // needs samples; then its statistics, with moments up to max_degree at least.
  ClusterPart face_part(std::uint32_t face, int max_degree, Scratch& scratch, int pin,
                        ClusterStats& fallback_stats, FaceCorners& fallback_corners) const {
    const std::uint32_t entry = face % Scratch::kCachedFaces;
    if (std::find(scratch.pinned.begin(), scratch.pinned.end(), entry) != scratch.pinned.end()) {
      if (read_face(face, max_degree, fallback_stats, fallback_corners)) return fallback_corners;
      return fallback_stats;
    }
    scratch.pinned[pin] = entry;
    if (scratch.cached_face[entry] != face ||
        (!scratch.cached_by_corners[entry] && scratch.cached_degree[entry] < max_degree)) {
      scratch.cached_face[entry] = face;
      scratch.cached_by_corners[entry] =
          read_face(face, max_degree, scratch.cached_stats[entry], scratch.cached_corners[entry]);
      scratch.cached_degree[entry] = max_degree;
    }
    if (scratch.cached_by_corners[entry]) return scratch.cached_corners[entry];
    return scratch.cached_stats[entry];
  }

  // Reads a face into `corners` (true), or into `stats` (moments up to max_degree) when its
  // corners do not apply.
  bool read_face(std::uint32_t face, int max_degree, ClusterStats& stats,
                 FaceCorners& corners) const {
    if (by_corners_ && graph_->face_corners(face, corners)) return true;
    graph_->face_stats(face, stats, selector_.needs_samples(), max_degree);
    return false;
  }

  // Whether a pair of faces of this many triangles is read by its corners (then it keeps no
  // statistics at all: uniting the faces' corners is cheap).
  bool pair_by_corners(std::uint32_t triangles) const {
    return by_corners_ && triangles <= FaceCorners::kMaxTriangles;
  }
  // The dual edge between the two faces of the cluster in `slot` if it is a pair read by its
  // faces' corners (not read: for prefetches), else nullptr.
  const DualEdge* pair_faces(std::uint32_t slot) const {
    const std::uint32_t index = slots_[slot].stats;
    if (index == kNone || !(index & kPairTag) || !pair_by_corners(slots_[slot].triangles))
      return nullptr;
    return &graph_->edges()[index & ~kPairTag];
  }

  // Pairs of faces are most of the merged clusters alive at once (all of them at the peak on a
  // subdivided mesh, 40% on a scan): reading them from their two faces saves their statistics'
  // 568 bytes each. A pair is read by its corners when they are few (see pair_by_corners());
  // else the most recent pairs' statistics are kept in a small cache (they are next to the
  // clusters that grow): most reads of them hit it.
  void store_pair(std::uint32_t slot, std::uint32_t edge_id, std::uint32_t triangles,
                  ClusterStats&& stats) {
    release_stats(slot);
    const std::uint32_t key = kPairTag | edge_id;
    slots_[slot].stats = key;
    if (pair_by_corners(triangles)) return;
    CachedPair& entry = pair_cache_[key % kCachedPairs];
    entry.key = key;
    entry.stats = std::move(stats);
  }

  void store_stats(std::uint32_t slot, ClusterStats&& stats) {
    std::uint32_t& index = slots_[slot].stats;
    if (index == kNone || (index & kPairTag)) {
      if (free_stats_.empty()) {
        index = static_cast<std::uint32_t>(stats_.size());
        stats_.push_back(std::move(stats));
        stats_used_.store(stats_.size() * sizeof(ClusterStats), std::memory_order_relaxed);
        return;
      }
      index = free_stats_.back();
      free_stats_.pop_back();
    }
    stats_[index] = std::move(stats);
  }

  void release_stats(std::uint32_t slot) {
    std::uint32_t& index = slots_[slot].stats;
    if (index != kNone && !(index & kPairTag)) free_stats_.push_back(index);
    index = kNone;
  }

  detail::SelectedModel select(const ClusterView& cluster, const LiveEdge& e) const {
    if (!options_.exact_costs) return selector_.select(cluster);
    const detail::ExactError exact = [&](const Primitive& primitive) {
      double sum = 0;
      for (std::uint32_t slot : {e.a, e.b})
        for (std::uint32_t f = face_list_head_[slot]; f != kNone; f = next_face_[f])
          for (std::uint32_t t = graph_->first_triangle(f); t < graph_->first_triangle(f + 1);
               ++t) {
            const Triangle corners = graph_->corners(t);
            const std::array<double, 3> w = graph_->corner_weights(t);
            for (int c = 0; c < 3; ++c) {
              const Eigen::Vector3d& x = graph_->position(corners[c]);
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
    if (tape_) [[unlikely]]
      return taped_evaluation(id, scratch);
    LiveEdge& e = edges_[id];
    const int degree = selector_.moment_degree(slots_[e.a].triangles + slots_[e.b].triangles);
    const ClusterPart a = part_of(e.a, scratch, 0, degree);  // (part 0 first)
    const ClusterPart b = part_of(e.b, scratch, 1, degree);
    const ClusterView cluster(a, b, shared_edges(id));
    const detail::SelectedModel model = select(cluster, e);
    if (lazy_) e.raise_cost_bound(model.superset_cost_bound);
    return {model.cost, true, model.fit.primitive.type, id};
  }

  // evaluate() for a benchmark's tape (evaluation_tape.hpp): the next recorded outcome instead of
  // an evaluation, or an evaluation recorded. Out of line, so that the loop's code stays as
  // without it.
  [[gnu::noinline, gnu::cold]] QueuedCandidate taped_evaluation(std::uint32_t id,
                                                                Scratch& scratch) {
    LiveEdge& e = edges_[id];
    if (tape_->mode == detail::EvaluationTape::Mode::Replay) {
      if (tape_->next == tape_->outcomes.size())
        throw Error("evaluation tape: the build evaluates more candidates than it recorded");
      const detail::EvaluationOutcome& outcome = tape_->outcomes[tape_->next++];
      if (lazy_) e.raise_cost_bound(outcome.cost_bound);
      return {outcome.cost, true, outcome.type, id};
    }
    detail::EvaluationTape* const tape = std::exchange(tape_, nullptr);
    const QueuedCandidate evaluated = evaluate(id, scratch);
    tape_ = tape;
    // The edge's bound as raised (raising it again to that on replay gives the same bound).
    tape_->outcomes.push_back({evaluated.cost, e.cost_bound, evaluated.type()});
    return evaluated;
  }

  // What a bound's check reads of a cluster: its weight, centroid and spread Σ w |x − c|².
  struct PartSpread {
    double weight = 0;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    double spread = 0;
  };
  static constexpr double kNotRead = std::numeric_limits<double>::quiet_NaN();
  static PartSpread spread_of(const ClusterStats& stats) {
    return {stats.moments.weight(), stats.moments.origin(), stats.moments.second_moment().trace()};
  }
  // The union of two parts' spreads: Σ w |x − c|² adds w_a w_b / (w_a + w_b) |c_a − c_b|², a sum
  // symmetric in a and b to the last bit. Weight 0 if either part has none (then no bound).
  static PartSpread united(const PartSpread& a, const PartSpread& b) {
    if (!(a.weight > 0) || !(b.weight > 0)) return {};
    const double weight = a.weight + b.weight;
    return {weight, (a.weight * a.centroid + b.weight * b.centroid) / weight,
            a.spread + b.spread +
                a.weight * b.weight / weight * (a.centroid - b.centroid).squaredNorm()};
  }
  // A face's spread from its corners alone: a quarter of the instructions of a full read
  // (face_corners(), with normals and offsets), which the check needs for each neighbour of every
  // new cluster. In two passes about the centroid, as the reads' (a one-pass Σ w |x|² − w |c|²
  // would lose the spread of a small face far from the origin); the round-off differs from
  // theirs by far less than the check's margin.
  PartSpread face_spread(std::uint32_t face) const {
    const std::uint32_t begin = graph_->first_triangle(face);
    const std::uint32_t count = graph_->first_triangle(face + 1) - begin;
    if (count > FaceCorners::kMaxTriangles)  // (a polygon of many triangles: rare)
      return spread_of(graph_->face_stats(face, false, 2).centred(2));
    std::array<Triangle, FaceCorners::kMaxTriangles> corners;
    std::array<std::array<double, 3>, FaceCorners::kMaxTriangles> weights;
    PartSpread result;
    Eigen::Vector3d weighted_sum = Eigen::Vector3d::Zero();
    for (std::uint32_t i = 0; i < count; ++i) {
      corners[i] = graph_->corners(begin + i);
      weights[i] = graph_->corner_weights(begin + i);
      for (int k = 0; k < 3; ++k) {
        weighted_sum += weights[i][k] * graph_->position(corners[i][k]);
        result.weight += weights[i][k];
      }
    }
    if (!(result.weight > 0)) return {};
    result.centroid = weighted_sum / result.weight;
    for (std::uint32_t i = 0; i < count; ++i)
      for (int k = 0; k < 3; ++k)
        result.spread +=
            weights[i][k] * (graph_->position(corners[i][k]) - result.centroid).squaredNorm();
    return result;
  }
  // A face's spread, read once: a face is checked as the neighbour of about five new clusters
  // (bunny00 with planes: 3% fewer build instructions, for 40 bytes a face). The table is made at
  // the first check, so never when some enabled type gives no bound (the cylinder).
  PartSpread cached_face_spread(std::uint32_t face) {
    if (face_spreads_.empty()) {
      detail::reserve_huge_to_fill(face_spreads_, graph_->face_count());
      face_spreads_.assign(graph_->face_count(), PartSpread{kNotRead, Eigen::Vector3d::Zero(), 0});
    }
    PartSpread& cached = face_spreads_[face];
    if (std::isnan(cached.weight)) cached = face_spread(face);
    return cached;
  }
  // The spread of the cluster in `slot`: a stored cluster's from its statistics, a face's and a
  // pair's from their faces' (or a pair's cached statistics).
  PartSpread part_spread(std::uint32_t slot) {
    const std::uint32_t index = slots_[slot].stats;
    if (index == kNone) return cached_face_spread(slot);
    if (index & kPairTag) {
      if (!pair_by_corners(slots_[slot].triangles)) {
        const CachedPair& cached = pair_cache_[index % kCachedPairs];
        if (cached.key == index) return spread_of(cached.stats);
      }
      const DualEdge& pair = graph_->edges()[index & ~kPairTag];
      return united(cached_face_spread(pair.first), cached_face_spread(pair.second));
    }
    return spread_of(stats_[index]);
  }

  // The cost bound of live edge `e`, between the new cluster in `merged_slot` and a neighbour, if
  // it is above `defer_above` (see kDeferFactor) and holds for their union, else 0. The new
  // cluster's spread is read once for all its edges, into `merged` on first use. A cost that would
  // snap to zero (at most zero_cost_tolerance × the union's spread, for the cheapest type) can be
  // below any bound from a subset, so the bound holds only above that level. The union's spread
  // is exact from the parts' (united()); the factor 2 covers round-off. A check that fails for
  // round-off costs an evaluation, never another tree.
  double queued_bound(const LiveEdge& e, std::uint32_t merged_slot, double defer_above,
                      std::optional<PartSpread>& merged) {
    if (!(e.cost_bound > defer_above)) return 0;  // (a zero bound too: defer_above >= 0)
    if (!merged) merged = part_spread(merged_slot);
    const PartSpread pair = united(*merged, part_spread(other_end(e, merged_slot)));
    if (!(pair.weight > 0)) return 0;
    return e.cost_bound > 2 * max_penalty_ * options_.zero_cost_tolerance * pair.spread
               ? e.cost_bound
               : 0.0;
  }

  // Moves b's edges to a's slot, where two edges to a common neighbour become one (their mesh
  // edges summed, the second killed), and returns the head of the merged list: a's kept links,
  // then b's, in their order.
  std::uint32_t relink(std::uint32_t slot_a, std::uint32_t slot_b) {
    std::uint32_t head = kNone;
    std::uint32_t* tail = &head;
    for (std::uint32_t slot : {slot_a, slot_b}) {
      for (std::uint32_t link = slots_[slot].first_link, next; link != kNone; link = next) {
        next = next_link_[link];
        const std::uint32_t id = link / 2;
        LiveEdge& e = edges_[id];
        if (!e.alive()) continue;
        std::uint32_t& marker = slots_[other_end(e, slot)].marker;
        if (marker == kNone) {
          marker = id;
          (e.a == slot ? e.a : e.b) = slot_a;
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
    slots_[slot_a].first_link = head;
    slots_[slot_b].first_link = kNone;
    for (std::uint32_t link = head; link != kNone; link = next_link_[link])
      slots_[other_end(edges_[link / 2], slot_a)].marker = kNone;
    return head;
  }

  // Asks for the cache lines the evaluation of candidate `id` with the cluster in `slot` reads
  // most: that cluster's statistics if stored (its triangles if a face), the mesh edges between
  // the two clusters, the candidate's place in the queue.
  void prefetch_candidate(std::uint32_t id, std::uint32_t slot) const {
    prefetch_cluster(slot);
    queue_.prefetch(id);
    prefetch_shared_edges(id);
  }

  // The first link of the chain a cluster's read follows: a stored cluster's (or cached pair's)
  // statistics, a face's triangles, the dual edge of a pair read by its faces' corners.
  void prefetch_cluster(std::uint32_t slot) const {
    const std::uint32_t index = slots_[slot].stats;
    auto prefetch_stats = [](const ClusterStats& stats) {
      const char* bytes = reinterpret_cast<const char*>(&stats);
      for (std::size_t offset = 0; offset < sizeof(ClusterStats); offset += 64)
        __builtin_prefetch(bytes + offset);
    };
    if (index == kNone)
      graph_->prefetch_face(slot);
    else if (!(index & kPairTag))
      prefetch_stats(stats_[index]);
    else if (const DualEdge* pair = pair_faces(slot))
      __builtin_prefetch(pair);
    else if (pair_cache_[index % kCachedPairs].key == index)
      prefetch_stats(pair_cache_[index % kCachedPairs].stats);
  }
  // The next link, once the first has arrived: a face's corners' positions, a pair's triangles.
  void prefetch_faces(std::uint32_t slot) const {
    if (slots_[slot].stats == kNone) {
      graph_->prefetch_face_corners(slot);
    } else if (const DualEdge* pair = pair_faces(slot)) {
      graph_->prefetch_face(pair->first);
      graph_->prefetch_face(pair->second);
    }
  }
  // The last link of a pair's chain: its faces' corners' positions.
  void prefetch_pair_corners(std::uint32_t slot) const {
    if (const DualEdge* pair = pair_faces(slot)) {
      graph_->prefetch_face_corners(pair->first);
      graph_->prefetch_face_corners(pair->second);
    }
  }
  // The mesh edges between the two clusters of live edge `id` (what shared_edges() reads).
  void prefetch_shared_edges(std::uint32_t id) const {
    const std::uint32_t pooled = edges_[id].combined_shared;
    if (pooled == kNone)
      __builtin_prefetch(&graph_->edges()[id]);
    else
      __builtin_prefetch(&combined_shared_[pooled]);
  }

  // The clusters of the candidate likely to be merged next: the top's runner-up, right 91% of
  // the time on bunny00. Its data has mostly left the caches since it was evaluated, and the next
  // merge would read it in chains of misses (the edge, the slots, the statistics or the faces'
  // triangles, the corners' positions; and for the relinking each cluster's adjacency list, one
  // link after another). So it is asked for in stages through the current merge, each stage
  // reading what the one before asked for. A wrong guess costs a few loads.
  struct Lookahead {
    std::uint32_t edge = kNone;
    std::array<std::uint32_t, 2> slots{kNone, kNone};  // kNone: none, or one the merge just read
    // Per slot, where the next link of its adjacency list is to be read (its slot's first_link,
    // then the last link's next_link_ entry); null: none, or the list's end.
    std::array<const std::uint32_t*, 2> next_link{nullptr, nullptr};
  };
  // Stage 1, as the merge starts: the edge.
  Lookahead lookahead_edge() const {
    Lookahead next;
    const std::uint32_t p = queue_.runner_up();
    if (batched_ || p == CandidateQueue::kAbsent) return next;
    next.edge = queue_.at(p).id;
    __builtin_prefetch(&edges_[next.edge]);
    return next;
  }
  // Stage 2, after relink(): the slots and the mesh edges between them.
  void lookahead_slots(Lookahead& next, std::uint32_t slot_a, std::uint32_t slot_b) const {
    if (next.edge == kNone) return;
    const LiveEdge& e = edges_[next.edge];
    if (!e.alive()) return;
    prefetch_shared_edges(next.edge);
    for (int k = 0; k < 2; ++k) {
      const std::uint32_t slot = k == 0 ? e.a : e.b;
      if (slot == slot_a || slot == slot_b) continue;
      next.slots[k] = slot;
      next.next_link[k] = &slots_[slot].first_link;  // (read at stage 3, once the slot is here)
      __builtin_prefetch(&slots_[slot]);
    }
  }
  // Stages 3 to 5 (after the merged cluster's fit, before and after its candidates' evaluation):
  // each link of the clusters' chains in turn, and one more link of each adjacency list. The
  // lists are about six links each and these three stages ask for half of them (about 3% of
  // bunny00's build: docs/method.md).
  template <class Prefetch>
  void lookahead(Lookahead& next, Prefetch prefetch) const {
    for (std::uint32_t slot : next.slots)
      if (slot != kNone) (this->*prefetch)(slot);
    for (const std::uint32_t*& at : next.next_link) {
      if (!at) continue;
      const std::uint32_t link = *at;
      if (link == kNone) {
        at = nullptr;
        continue;
      }
      __builtin_prefetch(&next_link_[link]);
      __builtin_prefetch(&edges_[link / 2]);
      at = &next_link_[link];
    }
  }

  // Applies the candidate's merge.
  void merge(const QueuedCandidate& candidate) {
    const std::uint32_t edge_id = candidate.id;
    const LiveEdge edge = edges_[edge_id];
    const std::uint32_t slot_a = edge.a, slot_b = edge.b;
    const std::uint32_t a = slots_[slot_a].node, b = slots_[slot_b].node;
    const std::uint32_t faces = slots_[slot_a].faces + slots_[slot_b].faces;
    const std::uint32_t triangles = slots_[slot_a].triangles + slots_[slot_b].triangles;
    // A copy: combining edges in relink() may move the pool it is in.
    const EdgeStats shared = shared_edges(edge_id);
    const int degree = selector_.stored_moment_degree();
    const ClusterPart part_a = part_of(slot_a, scratch_[0], 0, degree);  // (part 0 first)
    const ClusterPart part_b = part_of(slot_b, scratch_[0], 1, degree);
    const ClusterView cluster(part_a, part_b, shared);
    // Two independent jobs: the new cluster's edges, and its fit and statistics (the type is
    // known: only its fit is needed, and it has the candidate's cost exactly). On two threads
    // only when a fit is costly; else in this order, so that what the new cluster's candidates
    // will read arrives while its fit is computed.
    std::uint32_t head = kNone;
    detail::SelectedModel model;
    Lookahead next = lookahead_edge();
    auto jobs = [&](std::size_t job, unsigned) {
      if (job == 0) {
        kill_edge(edge_id);
        head = relink(slot_a, slot_b);
        // What the new cluster's candidates will read arrives while the other job runs.
        for (std::uint32_t link = head; link != kNone; link = next_link_[link])
          prefetch_candidate(link / 2, other_end(edges_[link / 2], slot_a));
        lookahead_slots(next, slot_a, slot_b);
      } else {
        model = options_.exact_costs ? select(cluster, edge)
                                     : selector_.refit(cluster, candidate.type());
        if (!(faces == 2 && pair_by_corners(triangles))) merged_ = cluster.stats(degree);
      }
    };
    pool_.run(2, jobs, parallel_from_);
    lookahead(next, &Impl::prefetch_cluster);
    lookahead_ = next;
    const std::uint32_t node = next_node();

    Merge record;
    record.first = std::min(a, b);
    record.second = std::max(a, b);
    record.cost = model.cost;
    record.error = model.fit.error;
    record.weight = cluster.weight();
    record.face_count = faces;
    record.primitive = graph_->frame().to_input(model.fit.primitive);
    merges_.push_back(record);
    merges_used_.store(merges_.size() * sizeof(Merge), std::memory_order_relaxed);
    max_cost_ = std::max(max_cost_, model.cost);

    keep_merged(slot_a, slot_b, edge_id, faces, triangles, node);
    if (batched_) {
      formed_at_[slot_a] = static_cast<std::uint32_t>(merges_.size());
      dirty_slots_.push_back(slot_a);
    } else {
      queue_candidates_of(slot_a, head);
    }
  }

  // merge_batch_tolerance > 0: one merge of the open batch (see HierarchyOptions), closing and
  // opening batches on the way.
  bool batched_step() {
    for (;;) {
      if (queue_.empty()) {
        if (dirty_slots_.empty()) return false;
        close_batch();
        continue;
      }
      const QueuedCandidate top = queue_.top();
      if (batch_limit_ >= 0 && top.cost > batch_limit_) {
        close_batch();
        continue;
      }
      if (stale(top.id)) {  // (every entry is exact: no bounds in batches)
        reevaluate(top.id);
        continue;
      }
      // A batch opens at the cheapest candidate's true cost.
      if (batch_limit_ < 0) batch_limit_ = top.cost * (1 + options_.merge_batch_tolerance);
      const QueuedCandidate chosen = top.cost > 0 ? settle_tie(top) : top;
      if (stale(chosen.id)) {
        reevaluate(chosen.id);
        continue;
      }
      merge(chosen);
      return true;
    }
  }

  // Whether a cluster of the edge formed after the edge's cost was taken (batched merging).
  bool stale(std::uint32_t id) const {
    const LiveEdge& e = edges_[id];
    return evaluated_at_[id] < std::max(formed_at_[e.a], formed_at_[e.b]);
  }

  // A candidate evaluated alone, with its degree.
  void reevaluate(std::uint32_t id) {
    QueuedCandidate c = evaluate(id, scratch_[0]);
    if (c.cost == 0) c.set_degree(merged_degree(edges_[id].a, edges_[id].b));
    evaluated_at_[id] = static_cast<std::uint32_t>(merges_.size());
    requeue(c);
    ++evaluations_;
  }

  // Evaluates every candidate the batch's merges left stale, on all threads, and opens the next.
  void close_batch() {
    const auto now = static_cast<std::uint32_t>(merges_.size());
    batch_.clear();
    batch_slots_.clear();
    for (std::uint32_t slot : dirty_slots_) {
      if (slots_[slot].node == kNone) continue;  // merged into another slot since
      // Unlinks the edges later merges of its neighbours killed (mark_neighbours() needs live
      // lists).
      for (std::uint32_t* link = &slots_[slot].first_link; *link != kNone;) {
        const std::uint32_t id = *link / 2;
        if (!edges_[id].alive()) {
          *link = next_link_[*link];
          continue;
        }
        link = &next_link_[*link];
        if (!stale(id)) continue;
        evaluated_at_[id] = now;
        batch_.emplace_back(0.0, false, PrimitiveType::Plane, id);
        batch_slots_.push_back(slot);
      }
    }
    dirty_slots_.clear();
    batch_limit_ = -1;
    evaluate_and_queue_batch([this](std::size_t i) { return batch_slots_[i]; });
  }

  // The merged cluster (node `node`, of `faces` faces and `triangles` triangles, its statistics in
  // merged_) lives in slot_a; slot_b's is released. `edge_id` joined them.
  void keep_merged(std::uint32_t slot_a, std::uint32_t slot_b, std::uint32_t edge_id,
                   std::uint32_t faces, std::uint32_t triangles, std::uint32_t node) {
    release_stats(slot_b);
    if (faces == 2)
      store_pair(slot_a, edge_id, triangles, std::move(merged_));
    else
      store_stats(slot_a, std::move(merged_));
    Slot& kept = slots_[slot_a];
    kept.faces = faces;
    kept.triangles += slots_[slot_b].triangles;
    kept.min_face = std::min(kept.min_face, slots_[slot_b].min_face);
    kept.node = node;
    slots_[slot_b].node = kNone;
    if (options_.exact_costs) {
      next_face_[face_list_tail_[slot_a]] = face_list_head_[slot_b];
      face_list_tail_[slot_a] = face_list_tail_[slot_b];
    }
  }

  // The candidates of the cluster in `slot` (its adjacency list from `head`), after its merge.
  void queue_candidates_of(std::uint32_t slot, std::uint32_t head) {
    // The new cluster's candidates: those under a bound that holds and is at least kDeferFactor
    // times the queue's top key wait in the queue (a zero bound would reach the top before the
    // next merge anyway; while zero-cost merges remain, the top's key is zero and every positive
    // bound that holds waits), the others are evaluated, on all threads, and queued in list order.
    batch_.clear();
    std::optional<PartSpread> merged;
    const double defer_above = queue_.empty() ? 0 : kDeferFactor * queue_.top().cost;
    for (std::uint32_t link = head; link != kNone; link = next_link_[link]) {
      const std::uint32_t id = link / 2;
      const double bound = lazy_ ? queued_bound(edges_[id], slot, defer_above, merged) : 0;
      if (bound > 0)
        requeue({bound, false, PrimitiveType::Plane, id});
      else
        batch_.emplace_back(0.0, false, PrimitiveType::Plane, id);
    }
    // The faces' corners, now that their triangles have arrived; a pair's faces' triangles, now
    // that its dual edge has (their corners come one candidate ahead, in the batch's evaluation).
    for (const QueuedCandidate& queued : batch_) prefetch_faces(other_end(edges_[queued.id], slot));
    lookahead(lookahead_, &Impl::prefetch_faces);
    evaluate_and_queue_batch([slot](std::size_t) { return slot; });
  }

  // Evaluates the candidates in batch_ (on all threads if they are many or costly) and queues
  // them in order. A zero-cost candidate's merged degree is counted from the cluster in
  // slot_of(i), the end that collected it (batch_ holds each slot's candidates in one run).
  template <class SlotOf>
  void evaluate_and_queue_batch(SlotOf slot_of) {
    auto evaluate_batch = [&](std::size_t i, unsigned thread) {
      if (i + 1 < batch_.size())
        prefetch_pair_corners(other_end(edges_[batch_[i + 1].id], slot_of(i + 1)));
      batch_[i] = evaluate(batch_[i].id, scratch_[thread]);
    };
    pool_.run(batch_.size(), evaluate_batch, parallel_from_);
    lookahead(lookahead_, &Impl::prefetch_pair_corners);
    for (const QueuedCandidate& evaluated : batch_) queue_.prefetch_node(evaluated.id);
    std::uint32_t marked = kNone;
    for (std::size_t i = 0; i < batch_.size(); ++i) {
      QueuedCandidate& evaluated = batch_[i];
      if (evaluated.cost == 0) {
        const std::uint32_t slot = slot_of(i);
        if (slot != marked) mark_neighbours(marked = slot);
        evaluated.set_degree(degree_with_marked(slot, other_end(edges_[evaluated.id], slot)));
      }
      requeue(evaluated);
    }
    evaluations_ += batch_.size();
  }

  // Stamps the neighbours of the cluster in `slot` (for degree_with_marked()) and remembers
  // their number.
  void mark_neighbours(std::uint32_t slot) {
    ++current_stamp_;
    marked_degree_ = 0;
    for (std::uint32_t link = slots_[slot].first_link; link != kNone; link = next_link_[link]) {
      slots_[other_end(edges_[link / 2], slot)].stamp = current_stamp_;
      ++marked_degree_;
    }
  }

  // merged_degree(marked, other) for `other` a neighbour of the cluster whose neighbours
  // mark_neighbours() just stamped: |adj(m) \ {o}| + |adj(o) \ {m}| − |adj(m) ∩ adj(o)|, in
  // O(deg o) instead of O(deg m + deg o) (a large flat region next to single faces gets all its
  // candidates at zero cost, each needing its degree). Unlinks o's dead edges on the way.
  std::uint32_t degree_with_marked(std::uint32_t marked, std::uint32_t other) {
    std::uint32_t degree = marked_degree_ - 1;
    std::uint32_t* link = &slots_[other].first_link;
    while (*link != kNone) {
      const LiveEdge& e = edges_[*link / 2];
      if (!e.alive()) {
        *link = next_link_[*link];
        continue;
      }
      link = &next_link_[*link];
      const std::uint32_t neighbour = other_end(e, other);
      if (neighbour != marked && slots_[neighbour].stamp != current_stamp_) ++degree;
    }
    return degree;
  }

  // What only the merge loop needs (about two thirds of the peak memory) is freed before the
  // caller goes on with the tree.
  void release_working_memory() {
    warmer_.stop();  // before the storage it warms goes
    auto release = [](auto& vector) { std::decay_t<decltype(vector)>().swap(vector); };
    release(stats_);
    release(free_stats_);
    release(pair_cache_);
    release(slots_);
    release(next_link_);
    release(edges_);
    release(combined_shared_);
    release(free_combined_shared_);
    queue_.clear();
    release(tied_);
    release(queued_pairs_);
    release(next_face_);
    release(face_list_head_);
    release(face_list_tail_);
    release(formed_at_);
    release(evaluated_at_);
    release(dirty_slots_);
    release(batch_slots_);
    release(face_spreads_);
  }

  // Components are joined in the order of their lowest face, each trailing merge costed above
  // every real one so that cuts and dendrograms keep them last.
  void add_trailing_merges() {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> roots;  // (lowest face, slot)
    for (std::uint32_t slot = 0; slot < slots_.size(); ++slot)
      if (slots_[slot].node != kNone) roots.emplace_back(slots_[slot].min_face, slot);
    std::sort(roots.begin(), roots.end());
    const double cost = max_cost_ > 0 ? 2 * max_cost_ : 1.0;
    std::uint32_t joined = slots_[roots.front().second].node;
    double weight = part_of(roots.front().second, scratch_[0], 0, 2).weight();
    std::uint32_t faces = slots_[roots.front().second].faces;
    for (std::size_t i = 1; i < roots.size(); ++i) {
      const std::uint32_t slot = roots[i].second, other = slots_[slot].node;
      Merge record;
      record.first = std::min(joined, other);
      record.second = std::max(joined, other);
      record.cost = cost;
      record.weight = weight += part_of(slot, scratch_[0], 0, 2).weight();
      record.face_count = faces += slots_[slot].faces;
      record.trailing = true;
      joined = next_node();
      merges_.push_back(record);
    }
  }

  std::shared_ptr<const Mesh> mesh_;
  HierarchyOptions options_;
  detail::ModelSelector selector_;
  detail::BatchPool pool_;
  std::vector<Scratch> scratch_;  // per thread of pool_
  std::unique_ptr<DualGraph> graph_;
  // Per face of graph_, its input face, when graph_ is in spatial order (else empty).
  std::vector<std::uint32_t> original_face_;
  std::vector<ClusterStats> stats_;  // merged clusters' statistics, pooled
  // Statistics of recent pairs by key (kPairTag | dual edge), direct-mapped: see store_pair().
  // Written between batches only.
  static constexpr std::uint32_t kCachedPairs = 1024;
  struct CachedPair {
    std::uint32_t key = kNone;
    ClusterStats stats;
  };
  std::vector<CachedPair> pair_cache_;     // kCachedPairs entries
  std::vector<std::uint32_t> free_stats_;  // unused entries of stats_
  std::vector<Slot> slots_;                // per input face
  // Adjacency as intrusive lists: link 2 id + side is edge id on the list of the slot of its
  // a (side 0) or b (side 1) cluster, from Slot::first_link. Dead edges are unlinked lazily.
  std::vector<std::uint32_t> next_link_;  // per link
  std::vector<LiveEdge> edges_;
  std::vector<EdgeStats> combined_shared_;  // see LiveEdge::combined_shared
  std::vector<std::uint32_t> free_combined_shared_;
  std::vector<Merge> merges_;
  std::uint32_t current_stamp_ = 0;     // see Slot::stamp
  std::uint32_t marked_degree_ = 0;     // see mark_neighbours()
  std::vector<std::size_t> tied_;       // settle_tie()'s queue positions
  std::vector<QueuedCandidate> batch_;  // the candidates merge() evaluates
  std::vector<NodePair> queued_pairs_;  // per edge: see ComesFirst
  ClusterStats merged_;                 // merge()'s new statistics
  CandidateQueue queue_;
  std::vector<std::uint32_t> next_face_, face_list_head_, face_list_tail_;  // exact_costs only
  std::uint32_t total_merges_ = 0;
  double max_cost_ = 0;
  std::uint64_t evaluations_ = 0;
  detail::EvaluationTape* tape_ = nullptr;  // null unless a benchmark records or replays
  bool lazy_ = false;
  // Per face, for lazy bounds (see cached_face_spread()); weight kNotRead until read.
  std::vector<PartSpread> face_spreads_;
  Lookahead lookahead_;  // the last merge's guess at the next one
  // Batched merging only (see HierarchyOptions::merge_batch_tolerance): per slot, the merge
  // count just after its cluster formed; per edge, the merge count when its cost was taken.
  bool batched_ = false;
  std::vector<std::uint32_t> formed_at_, evaluated_at_;
  std::vector<std::uint32_t> dirty_slots_;  // slots whose cluster formed in the open batch
  std::vector<std::uint32_t> batch_slots_;  // close_batch(): the slot that collected batch_[i]
  double batch_limit_ = -1;                 // the open batch's largest cost; < 0: none open
  bool by_corners_ = false;                 // faces are read by their corners (see face_part())
  std::size_t parallel_from_ = 2;           // merge loop: jobs from which a batch is shared
  double max_penalty_ = 0;
  // Bytes of merges_ and stats_ in use, for warmer_, which faults their next pages in ahead of
  // the loop when merges_ takes kWarmFrom bytes or more (about 65,000 faces), kWarmLead ahead.
  static constexpr std::size_t kWarmFrom = std::size_t{8} << 20;
  static constexpr std::size_t kWarmLead = std::size_t{4} << 20;
  std::atomic<std::size_t> merges_used_{0}, stats_used_{0};
  detail::PageWarmer warmer_;  // last: stopped before the arrays it warms are destroyed
};

HierarchyBuilder::HierarchyBuilder(std::shared_ptr<const Mesh> mesh, HierarchyOptions options)
    : impl_(std::make_unique<Impl>(std::move(mesh), std::move(options))) {}
HierarchyBuilder::~HierarchyBuilder() = default;
HierarchyBuilder::Impl& HierarchyBuilder::impl() const {
  if (!impl_) throw Error("HierarchyBuilder: the build was ended by take_merges()");
  return *impl_;
}
bool HierarchyBuilder::step() {
  return impl().step();
}
std::uint32_t HierarchyBuilder::merge_count() const {
  return impl().merge_count();
}
std::uint32_t HierarchyBuilder::total_merge_count() const {
  return impl().total_merge_count();
}
std::uint64_t HierarchyBuilder::evaluation_count() const {
  return impl().evaluation_count();
}
std::span<const Merge> HierarchyBuilder::merges() const {
  return impl().merges();
}
std::vector<Merge> HierarchyBuilder::take_merges() {
  std::vector<Merge> merges = impl().take_merges();
  impl_.reset();
  return merges;
}
Hierarchy HierarchyBuilder::finish(const std::function<void(double)>& progress) {
  Impl::Parts parts = impl().finish(progress);
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
