#pragma once
/// @file dual_graph.hpp
/// The mesh as the engine sees it: its input faces as the nodes of a dual graph, its geometry in a
/// normalised working frame, its triangles consistently oriented, and the statistics of every
/// face.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "primseg/cluster_stats.hpp"
#include "primseg/mesh.hpp"
#include "primseg/primitive.hpp"

namespace primseg {

/// How much each triangle corner counts in a cluster's fitting error E = Σ w d².
enum class VertexWeights : std::uint8_t {
  /// w = triangle area / 3, so a vertex weighs a third of its cluster-incident area (the paper).
  Area = 0,
  /// w = 1 / (number of triangles incident on the vertex): a vertex inside a cluster weighs 1, a
  /// boundary vertex the fraction of its triangles in the cluster. (The paper weighs each vertex
  /// 1 in every cluster containing it; that is not additive over triangles, this is.)
  Uniform = 1,
};

/// Input coordinates x map to working coordinates (x − center) · 2^-exponent, with the exponent
/// chosen so that the mesh fits in [-1, 1]³. A power of two keeps the scaling exact: a mesh
/// scaled by 2^k has bit-identical working coordinates, and degree-4 moments of inputs near
/// 1e150 neither overflow nor lose precision.
struct WorkingFrame {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  int exponent = 0;

  double scale() const;  ///< 2^exponent: one working unit in input units.
  Eigen::Vector3d to_working(const Vec3& x) const;
  Vec3 to_input(const Eigen::Vector3d& x) const;
  /// A primitive's parameters from working to input units.
  Primitive to_input(const Primitive& working) const;
};

/// The frame for a mesh: centre and extent of the bounding box of its vertices.
WorkingFrame working_frame_for(const Mesh& mesh);

/// A dual edge: two input faces sharing at least one mesh edge.
struct DualEdge {
  std::uint32_t first, second;  ///< input faces, first < second
  /// The mesh edges the two faces share (working frame).
  EdgeStats shared;
};

class DualGraph;

/// A dual graph renumbered for memory locality by DualGraph::in_spatial_order(), and the way back
/// to the graph it came from.
struct SpatialOrder {
  std::unique_ptr<DualGraph> graph;
  /// The face of the original graph that each face of `graph` is, shape (F).
  std::vector<std::uint32_t> original_face;
  /// The index in the original graph's edges() of each of `graph`'s dual edges, shape (E).
  std::vector<std::uint32_t> original_edge;
};

/// Dual graph and working geometry of a mesh.
///
/// Non-manifold edges: the k >= 3 triangles on one mesh edge are sorted by index and joined in a
/// chain (t1–t2, t2–t3, …): k − 1 dual links, never k², and every face on the edge stays
/// connected to the others. Orientation propagates only across manifold edges.
///
/// The accessors that take a face, triangle or vertex index are the merge loop's: like a
/// vector's operator[], they do not check it (it must be below the mesh's count).
class DualGraph {
 public:
  /// Builds the graph of `mesh`, which must outlive it (the graph refers to it). Linear in T but
  /// for sorting the links of each face (O(T log T) at worst). `threads` as
  /// HierarchyOptions::threads: 0 uses all hardware threads; the graph is the same, bit for bit,
  /// for any number.
  DualGraph(const Mesh& mesh, VertexWeights weights, unsigned threads = 0);

  /// The mesh the graph was built on (for a graph from in_spatial_order(), the original graph's
  /// mesh, whose face, triangle and vertex ids are not this graph's).
  const Mesh& mesh() const { return *mesh_; }
  const WorkingFrame& frame() const { return frame_; }
  VertexWeights weights() const { return weights_; }
  std::uint32_t face_count() const {
    return static_cast<std::uint32_t>(first_triangle_.size() - 1);
  }
  /// Edge-connected components of the dual graph.
  std::uint32_t component_count() const { return component_count_; }
  /// Component of each input face, numbered by their lowest face, shape (F).
  const std::vector<std::uint32_t>& component_of_face() const { return component_of_face_; }
  /// Dual edges sorted by (first, second), each face pair once (from in_spatial_order(): sorted
  /// by their lower and higher face, first and second as they were in the original graph).
  const std::vector<DualEdge>& edges() const { return edges_; }

  /// Triangles of input face f: [first_triangle(f), first_triangle(f + 1)).
  std::uint32_t first_triangle(std::uint32_t f) const { return first_triangle_[f]; }
  /// Working-frame position of vertex v.
  const Eigen::Vector3d& position(std::uint32_t v) const { return positions_[v]; }
  /// Whether triangle t was flipped to orient its component consistently (outward when closed).
  bool flipped(std::uint32_t t) const { return (triangle_codes_[t] & 1) != 0; }
  /// Triangle t's vertices in the order every computation visits them: from the corner whose
  /// position is lexicographically smallest (the lowest index among equal positions), orientation
  /// kept. A file that lists a triangle from another corner thus gives the same tree, bit for bit.
  Triangle corners(std::uint32_t t) const;
  /// Area of triangle t (working frame; input area = ldexp(area, 2 · frame().exponent)).
  double triangle_area(std::uint32_t t) const;
  /// Weight of each corner of triangle t, in the order of corners(t) (working frame).
  std::array<double, 3> corner_weights(std::uint32_t t) const;
  /// Cache hints for a coming face_stats(f): prefetch_face() asks for the face's triangles,
  /// prefetch_face_corners(), a while later, for their corners' positions (it reads the
  /// triangles).
  void prefetch_face(std::uint32_t f) const;
  void prefetch_face_corners(std::uint32_t f) const;
  /// Statistics of input face f alone (its triangles and the edges between them), centred: about
  /// the weighted centroid of its corners (first moments zero). With `with_samples`, its corners
  /// in ClusterStats::samples too (for the torus). With max_degree 2 the moments of degree 3 and 4
  /// are left zero (enough for a plane).
  ClusterStats face_stats(std::uint32_t f, bool with_samples = false, int max_degree = 4) const;
  /// The same into `stats` (whatever it held before), reusing its storage.
  void face_stats(std::uint32_t f, ClusterStats& stats, bool with_samples, int max_degree) const;
  /// Input face f by its corners, about the same origin as face_stats(f). False, with `corners`
  /// unspecified, when f has more than FaceCorners::kMaxTriangles triangles.
  bool face_corners(std::uint32_t f, FaceCorners& corners) const;

  /// The same graph with its faces in a spatial order (the Morton order of their first
  /// triangle's centroid), its triangles in that order, its vertices in order of first use and
  /// its dual edges sorted again, so that faces near each other on the surface are near each
  /// other in memory: the merge loop's reads of faces, corners and edges then hit the caches far
  /// more often on meshes whose file lists faces in no spatial order (a scan's bunny00 does).
  /// Everything that does not name an id is the same, bit for bit: a face's statistics and
  /// corners, in the same order, the orientation, the components (numbered as before) and
  /// each dual edge's first and second face; corners() is the original graph's, renumbered
  /// (the lowest index among equal positions is the original vertex's). face_stats()'s samples
  /// take their priorities from triangle ids, which differ. Linear in F and E (but for sorting
  /// the edges inside polygon faces).
  SpatialOrder in_spatial_order() const;

 private:
  DualGraph() = default;
  // A triangle's area, centroid and corner weights from its corners(), for the accessors above
  // and for face_stats() and face_corners(); what the last two also share: the origin of face f's
  // statistics (its corners' weighted centroid from their weighted sum, or its first triangle's
  // centroid when they weigh nothing) and the mesh edges between f's own triangles.
  double area_of(const Triangle& corners) const;
  Eigen::Vector3d centroid_of(const Triangle& corners) const;
  std::array<double, 3> corner_weights_of(const Triangle& corners, double area) const;
  Eigen::Vector3d face_origin(std::uint32_t f, const Eigen::Vector3d& weighted_sum,
                              double weight) const;
  EdgeStats internal_edges_of(std::uint32_t f) const;

  // The triangles corners() reads: the mesh's, or in_spatial_order()'s renumbered own.
  std::span<const Triangle> triangles() const {
    return renumbered_triangles_.empty() ? std::span<const Triangle>(mesh_->triangles)
                                         : std::span<const Triangle>(renumbered_triangles_);
  }

  const Mesh* mesh_ = nullptr;
  VertexWeights weights_ = VertexWeights::Area;
  WorkingFrame frame_;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<std::uint32_t> first_triangle_;
  // Per triangle: bit 0 set when flipped(); bits 1 and 2 which of its listed corners corners()
  // starts from (0 in in_spatial_order()'s copy, whose triangles are stored in corners() order).
  // Found once here: comparing the corners' positions at every read cost 5% of the merge loop.
  std::vector<std::uint8_t> triangle_codes_;
  std::vector<std::uint32_t> valence_;
  std::vector<std::uint32_t> component_of_face_;
  std::uint32_t component_count_ = 0;
  std::vector<DualEdge> edges_;
  /// Edges inside polygon faces, sorted by face (only faces that have some).
  std::vector<std::pair<std::uint32_t, EdgeStats>> internal_edges_;
  /// From in_spatial_order(): the triangles, renumbered and already in corners() order.
  std::vector<Triangle> renumbered_triangles_;
};

}  // namespace primseg
