#pragma once
/// @file hierarchy.hpp
/// Greedy hierarchical face clustering (Attene, Falcidieno, Spagnuolo 2006, after Garland et al.
/// 2001): every input face starts as a cluster, the cheapest merge of two adjacent clusters is
/// applied until one cluster per connected component remains, and a cluster's cost is the
/// smallest L2 error over the enabled primitive types. The result is a full binary tree that can
/// be cut at any level without recomputation (cut.hpp).
///
/// One-shot use: `Hierarchy h = build_hierarchy(mesh);`. Step-by-step control (one merge per
/// step() call, to interleave with other work or report progress): HierarchyBuilder.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "primseg/dual_graph.hpp"
#include "primseg/mesh.hpp"
#include "primseg/primitive.hpp"

namespace primseg {

namespace detail {
class ModelSelector;
}  // namespace detail

/// How candidate merges are (re)evaluated after each merge.
enum class CandidateEvaluation {
  /// Every candidate of a new cluster is evaluated at once: the reference.
  Eager,
  /// A candidate waits in the queue under a lower bound of its cost (the cost of A∪C bounds that
  /// of A∪B∪C from below where the fit is an exact minimum of a sum of non-negative terms) and is
  /// evaluated only if it reaches the top; one whose bound is less than twice the queue's top key
  /// would mostly reach it soon, and is evaluated at once. Bounds are used only where they hold,
  /// so the tree is the same as Eager's, bit for bit. With cylinders enabled no bound is known for
  /// clusters of 4 triangles or more (the cylinder's axis is heuristic, so its cost is not a
  /// minimum) and it saves nothing; with planes and spheres it saves about a quarter of the
  /// evaluations (23% on fandisk, 26% on bunny00), with planes alone over a third (36%, 41%).
  Lazy,
};

/// The order the merge loop keeps faces in memory. The tree is the same, bit for bit, in any
/// order (node ids are the input's faces, and every sum and tie is taken as in the input's order);
/// only the time differs.
enum class FaceOrder {
  /// Spatial for a mesh of 131,072 faces or more whose file lists them in no spatial order: when
  /// fewer than half of its pairs of adjacent faces are listed within 1,024 places of each other.
  /// Measured on bunny00 midpoint-subdivided twice (1.2M faces, 0.1% noise) with its faces and
  /// vertices shuffled: 15.6 → 14.0 s. Listed as subdivided (81% of pairs near) the spatial
  /// order gains about what its copy of the dual graph costs, and so does bunny00 itself (75,408
  /// faces): those stay as listed.
  Automatic,
  /// On a copy of the dual graph renumbered in a spatial order (DualGraph::in_spatial_order()):
  /// the merge loop's reads of faces, corners and edges stay near each other in memory. Not with
  /// the torus (its samples' priorities come from triangle ids): the order is then AsListed.
  Spatial,
  /// In the order of the input.
  AsListed,
};

/// Options of the hierarchy. Defaults reproduce the paper's set-up with the robustness rules
/// documented here.
struct HierarchyOptions {
  /// Primitive types a cluster may be fitted with (at least one; each at most once).
  std::vector<PrimitiveType> primitives{PrimitiveType::Plane, PrimitiveType::Cylinder,
                                        PrimitiveType::Sphere};
  /// Corner weights of the fitting error.
  VertexWeights weights = VertexWeights::Area;
  /// Model selection: a type's error is multiplied by its penalty before types are compared, so
  /// a richer primitive wins only when it fits markedly better (noise alone lowers the error of a
  /// type with more parameters). Indexed by PrimitiveType. Ties go to the lower type value.
  std::array<double, 5> type_penalty{1.0, 1.5, 1.5, 1.75, 2.0};
  /// A cost at most this fraction of the merged cluster's spread Σ w |x − c|² counts as zero
  /// (round-off of an exact fit), so that flat or exactly curved regions tie and the tie rule
  /// (lowest merged degree) grows them evenly.
  double zero_cost_tolerance = 1e-12;
  /// Reference mode: the error of each fit is the exact Σ w d² over the clusters' vertices
  /// (Euclidean distance to the same fitted primitive), as the paper's prototype computed it.
  /// Cost O(|A| + |B|) per candidate instead of O(1): for comparison only.
  bool exact_costs = false;
  /// Threads for the parallel parts: the dual graph, the first evaluation of every candidate,
  /// and in the merge loop each merge's candidates and own fit where fits are costly (cones,
  /// tori, exact_costs), else only sets of 32 candidates or more (a batch of
  /// merge_batch_tolerance, a merge that leaves a cluster with that many neighbours): a merge's
  /// five or so cheap candidates are faster on the calling thread than handed to another core.
  /// With two or more, and from about 65,000 faces, one more thread faults in the pages the merge
  /// loop is about to write for the first time (Linux; mostly asleep). 0 uses all hardware
  /// threads. The tree is the same, bit for bit, for any number of threads.
  /// On a machine already loaded by other processes one thread can be the fastest. At most 256
  /// threads are used, and fewer if the system refuses to start more (a process or memory limit):
  /// the work then runs on those that started. The same holds for the `threads` of every other
  /// options struct.
  unsigned threads = 0;
  /// Candidate evaluation scheme (exact_costs forces Eager: Euclidean errors of algebraic fits
  /// are not minima, so no bound holds).
  CandidateEvaluation evaluation = CandidateEvaluation::Lazy;
  /// Approximate merge order, for speed; 0 (the default) is the exact greedy order. Above 0,
  /// merges are applied in batches: a batch opens at the cheapest candidate's cost c and takes
  /// every merge up to (1 + merge_batch_tolerance) c in queue order, keeping the candidates of
  /// the clusters it made under their old costs (a candidate that reaches the top with a stale
  /// cost is evaluated alone, on one thread); when it closes, every candidate it left stale is
  /// evaluated at once, on all threads. A cluster that grows several times in a batch evaluates
  /// its neighbours once. Where costs are monotone (a union costs at least what its parts do
  /// with the same neighbour) the old costs are lower bounds and the order is still exact; the
  /// cylinder's heuristic axis breaks that, so trees differ from the exact order (the README
  /// reports by how much). Deterministic, and the same for any number of threads. It pays where
  /// regions tie exactly (flat or exactly curved regions of many triangles), not on scans. Not
  /// stored in tree files (a tree read back reports 0). Must be finite and non-negative.
  double merge_batch_tolerance = 0;
  /// Approximate, for speed on two cores or more; 1 (the default) is the exact greedy order over
  /// the whole mesh. Above 1 the mesh is cut into this many regions of nearly equal face counts
  /// (recursive cuts at the median of the face centroids, along the longest side), each region
  /// is merged by itself, on its own thread (`threads` of them at once), until it has a 32nd of
  /// its faces as clusters, and the exact greedy order then goes on over the whole mesh from
  /// the regions' clusters. The tree's first merges are the regions', interleaved by cost, so
  /// the levels of more than F / 32 clusters have no cluster across a cut; coarser levels are
  /// merged as usual, from slightly other clusters. Deterministic, and the same for any number
  /// of threads. Regions have at least 4,096 faces: a smaller mesh gets fewer regions, or one.
  /// Where a region cannot stand for its part of the mesh (it links the triangles on a
  /// non-manifold edge otherwise than the whole mesh does, or its faces span less than the
  /// geometric range allows), the whole mesh is merged in the exact order.
  /// Not with exact_costs; not stored in tree files (a tree read back reports 1). At most 256.
  unsigned regions = 1;
  /// The order the merge loop keeps faces in memory (never the tree: see FaceOrder).
  FaceOrder face_order = FaceOrder::Automatic;
};

/// Throws InvalidInputError if options are unusable (no primitive, a type without a fitter, a
/// duplicate, a negative or non-finite penalty or tolerance).
void validate(const HierarchyOptions& options);

/// One merge of the tree. Node ids: input faces are leaves 0..F-1, merge i creates node F + i.
struct Merge {
  std::uint32_t first = 0, second = 0;  ///< children node ids, first < second
  /// Merge priority: the penalised error of the chosen type, zero-snapped (working frame:
  /// weight × length², see DualGraph's WorkingFrame). Trailing merges have a cost above all others.
  double cost = 0;
  /// L2 error Σ w d² of the chosen primitive (working frame, not penalised).
  double error = 0;
  /// Σ w of the merged cluster (working frame).
  double weight = 0;
  std::uint32_t face_count = 0;  ///< input faces in the merged cluster
  /// True for a merge joining two connected components after all real merges: no fit, never
  /// applied by cuts.
  bool trailing = false;
  /// Fitted primitive of the merged cluster, input units (type Plane and zeros when trailing).
  Primitive primitive;
};

/// The full merge tree of a mesh. Immutable; cheap to cut (cut.hpp).
class Hierarchy {
 public:
  /// A tree from its parts (as read from a tree file). Throws InvalidInputError unless `merges`
  /// form a binary tree over the mesh's F faces (F − 1 merges, children before parents) with what
  /// build_hierarchy guarantees: children as first < second, face counts and weights that add up,
  /// finite non-negative costs, errors and weights (costs at most 1e300, RMS errors at most 1e30
  /// working units); each real merge joins two clusters that share a mesh edge and carries a
  /// primitive of an enabled type with finite parameters and a unit axis; the F − C real merges
  /// come before the C − 1 trailing ones. O(E log F) for E pairs of adjacent faces.
  Hierarchy(std::shared_ptr<const Mesh> mesh, HierarchyOptions options, std::vector<Merge> merges);

  const Mesh& mesh() const { return *mesh_; }
  std::shared_ptr<const Mesh> shared_mesh() const { return mesh_; }
  const HierarchyOptions& options() const { return options_; }
  const DualGraph& graph() const { return *graph_; }
  std::uint32_t face_count() const { return mesh_->face_count(); }
  std::uint32_t node_count() const { return 2 * face_count() - 1; }
  std::uint32_t component_count() const { return graph_->component_count(); }
  /// F − 1 merges: F − C real ones in the greedy order, then C − 1 trailing ones.
  std::span<const Merge> merges() const { return merges_; }
  bool is_leaf(std::uint32_t node) const { return node < face_count(); }
  /// Parent of each node (UINT32_MAX for the root), shape (2F − 1).
  const std::vector<std::uint32_t>& parents() const { return parents_; }

  /// Fitted primitive of a node, input units (leaves are fitted on demand). This and the three
  /// accessors below throw InvalidInputError for a node id not below node_count().
  Primitive primitive(std::uint32_t node) const;
  /// L2 error of a node's primitive (working frame, as Merge::error; 0 for planar leaves).
  double error(std::uint32_t node) const;
  /// Σ w of a node (working frame).
  double weight(std::uint32_t node) const;
  /// Input faces of a node.
  std::uint32_t face_count(std::uint32_t node) const;
  /// sqrt(error / weight) in input units: the node's RMS distance estimate.
  double rms_estimate(std::uint32_t node) const;

  /// The merges as a matrix of shape (F − 1, 4): children ids, raw cost (not monotone: use
  /// scipy_linkage() in cut.hpp for SciPy), face count.
  std::vector<std::array<double, 4>> linkage() const;

 private:
  void check_node(std::uint32_t node) const;
  friend class HierarchyBuilder;
  // Adopts the dual graph the builder made (of this mesh, with these options' weights).
  Hierarchy(std::shared_ptr<const Mesh> mesh, HierarchyOptions options, std::vector<Merge> merges,
            std::unique_ptr<DualGraph> graph);

  std::shared_ptr<const Mesh> mesh_;
  HierarchyOptions options_;
  std::unique_ptr<DualGraph> graph_;
  std::vector<Merge> merges_;
  std::vector<std::uint32_t> parents_;
  // Leaves are not stored: their fits are recomputed by the merges' rule, made once here (making
  // it for each leaf cost a third of choose_level()).
  std::shared_ptr<const detail::ModelSelector> leaf_selector_;
};

/// Step-by-step construction of a Hierarchy.
class HierarchyBuilder {
 public:
  /// Prepares the dual graph and every initial candidate (O(F log F)). Throws InvalidInputError
  /// for invalid options or a mesh that fails Mesh::validate().
  explicit HierarchyBuilder(std::shared_ptr<const Mesh> mesh, HierarchyOptions options = {});
  ~HierarchyBuilder();
  HierarchyBuilder(const HierarchyBuilder&) = delete;
  HierarchyBuilder& operator=(const HierarchyBuilder&) = delete;

  /// Applies the next cheapest merge; false when no adjacent clusters remain.
  bool step();
  /// Number of merges applied so far (real merges only).
  std::uint32_t merge_count() const;
  /// Number of real merges the build will make: F − number of components.
  std::uint32_t total_merge_count() const;
  /// The merges applied so far: the first merge_count() merges of the tree finish() returns.
  /// Valid until the next step() or finish().
  std::span<const Merge> merges() const;
  /// Candidate merges evaluated so far (fits of a union of two clusters, including the first
  /// evaluation of every dual edge): what lazy evaluation saves.
  std::uint64_t evaluation_count() const;
  /// Runs the remaining steps, adds the trailing merges and returns the tree. `progress`, if
  /// given, is called now and then with the fraction done (0..1). Call it once: a second call
  /// throws Error.
  Hierarchy finish(const std::function<void(double)>& progress = {});
  /// Ends the build where it stands and hands over the merges applied so far, as merges() shows
  /// them (no trailing merges: a partial tree, for a build stopped at a level of the caller's
  /// choosing), without copying them. Every working array is freed at once. Afterwards every
  /// call but the destructor throws Error.
  std::vector<Merge> take_merges();

 private:
  class Impl;
  Impl& impl() const;
  std::unique_ptr<Impl> impl_;
};

/// Builds the whole hierarchy of a mesh (copies the mesh).
Hierarchy build_hierarchy(const Mesh& mesh, const HierarchyOptions& options = {});
/// Builds the whole hierarchy of a shared mesh (no copy).
Hierarchy build_hierarchy(std::shared_ptr<const Mesh> mesh, const HierarchyOptions& options = {});

}  // namespace primseg
