#pragma once
/// @file denoise.hpp
/// Denoising and sharp-feature recovery by snapping vertices onto the primitives of a
/// segmentation (Attene, Falcidieno, Spagnuolo 2006, section 7), and stylization (after Wu and
/// Kobbelt 2005).
///
/// A vertex inside a cluster moves to the closest point of the cluster's primitive. A vertex
/// shared by several clusters moves to the point nearest to it that minimises the sum of squared
/// distances to all the incident primitives: two planes put it on their intersection line, three
/// on their corner, which restores edges and corners that noise or resampling chamfered.
///
/// One-shot use: `Mesh clean = denoise(mesh, level_by_count(30));`. Step-by-step control (one
/// iteration at a time, or snapping onto a segmentation the caller already has): Denoiser.

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string_view>
#include <vector>

#include "primseg/auto_level.hpp"
#include "primseg/bilateral_smoothing.hpp"
#include "primseg/cut.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh.hpp"
#include "primseg/relations.hpp"

namespace primseg {

/// What a vertex shared by several clusters is snapped onto.
enum class SnapMode {
  /// Onto all incident primitives at once (least squares): denoising and feature recovery.
  AllIncident,
  /// Onto the nearest incident primitive only: every vertex lies on its own cluster's primitive,
  /// which stylizes a shape when the clusters are few.
  NearestIncident,
};

/// Options of the snapping. Defaults are those of `primseg denoise`.
struct DenoiseOptions {
  SnapMode mode = SnapMode::AllIncident;
  /// A vertex never moves farther than this many times its local edge length (the mean length of
  /// its incident edges in the input mesh); a move that would is replaced by one onto fewer
  /// primitives, or not made. Tied to the edge length rather than to the cluster's RMS, which
  /// would forbid the long moves that sharpen a chamfer. Infinity disables the bound; it is not
  /// applied in NearestIncident mode, whose moves are large by design. Must be positive.
  double max_move_edge_lengths = 4.0;
  /// Primitives whose normals at the snapped point make an angle below this (degrees, in
  /// [0, 90)) do not constrain the point along the direction they share: the least-squares system
  /// is solved with its eigenvalues below tan²(angle / 2) · largest eigenvalue dropped (minimum
  /// displacement along dropped directions). Two near-parallel planes thus give one averaged
  /// constraint instead of a far-away, ill-conditioned intersection.
  double min_crease_angle_degrees = 10.0;
  /// Before snapping, each cluster's primitive is refitted robustly on the vertices of its faces:
  /// vertices farther from the current fit than this many robust standard deviations (1.4826 ×
  /// the median distance) are left out and the rest refitted, three times. The vertices left out
  /// are those of chamfers and of misassigned faces along the borders, which tilt and offset the
  /// hierarchy's fit. Planes by weighted PCA; spheres, cylinders, cones and tori by
  /// Levenberg–Marquardt on the geometric distance (fit_geometric) from the hierarchy's fit,
  /// kept only when it lowers the error. 0 disables the refit.
  double refit_outlier_threshold = 2.5;
  /// The segmentation of each iteration is computed on a copy of the mesh smoothed by this many
  /// Taubin λ|μ steps (λ = 0.5, μ = −0.53, uniform weights), so that noise does not fragment it
  /// into small planes; the primitives are then refitted, and the vertices snapped, on the
  /// unsmoothed positions. 0 segments the mesh as it is.
  int smoothing_steps = 0;
  /// When set, the copy that is segmented is smoothed by bilateral normal filtering with these
  /// options (bilateral_smoothing.hpp) instead of Taubin steps (smoothing_steps must then be 0):
  /// noise is averaged on smooth parts while edges stay sharp, which segments noisy CAD parts
  /// better (fandisk with 0.3% noise: RMS 3.3x lower at K = 40 against 2.6x with 5 Taubin steps).
  std::optional<BilateralSmoothingOptions> bilateral_smoothing;
  /// After the refit, each face moves to the cluster, among its own and those of the faces
  /// sharing a vertex with it (but for a vertex at more than 64 clusters, such as a non-manifold
  /// book's spine, which offers none), whose primitive its corners are nearest to (sum of squared
  /// distances, measured on the segmented copy: smoothed when smoothing is on), and the
  /// primitives are refitted; this many passes, fewer when a pass moves nothing. The hierarchy's
  /// borders follow its greedy merges on the smoothed copy and zigzag across blends; the
  /// primitives, refitted on many vertices, know better where each surface ends (fandisk with
  /// 0.3% noise, bilateral smoothing: RMS 3.4x lower at K = 30 against 2.7x without). 0 keeps the
  /// hierarchy's labels. >= 0.
  int relabel_passes = 2;
  /// After relabelling, relations between the primitives are made exact where the fits agree
  /// with them within this many standard deviations (each fit's uncertainty from its residuals
  /// and Jacobian): plane normals and cylinder axes at most 20 degrees apart become parallel
  /// (one direction, estimated from all of them), directions at right angles become orthogonal,
  /// cylinders of one direction whose axes are one line become coaxial (each keeps its radius; a
  /// member whose fit the shared axis worsens beyond the same significance stays alone), and
  /// spheres centred on such a line are centred on it, and spheres whose centres agree share one
  /// (each keeps its radius). The members are refitted on their inliers (regularize_clusters()
  /// does the same for a level's fits, and also gives cylinders and spheres of equal radius one
  /// radius, the fragments of one face one plane and fillets tangency, which do not lower a
  /// snap's error and are left out here). A relation of the part (opposite faces of a box,
  /// a cylinder and its caps, a stepped shaft, a ball end, a box's corner) then costs one direction
  /// or one axis instead of one per primitive, which lowers what the fits leave of the noise: the
  /// generated noisy box and capped cylinder on their true regions (edges 2% of the diagonal) 12.0x
  /// → 18.0x and 13.5x → 23.9x lower RMS; fandisk with 0.3% noise on the clean mesh's 30
  /// clusters 5.5x → 6.7x, at the automatic level 3.79x → 4.07x. Needs the refit
  /// (refit_outlier_threshold > 0). 0 disables. >= 0.
  double relation_significance = 3.0;
  /// The automatic level (Denoiser::automatic_level) cuts a hierarchy without a significant jump
  /// at this multiple of the noise estimate (estimate_noise). Unset: by the copy that is
  /// segmented, about 1.4 times the noise left in it: 1.2 for the mesh as it is, 0.8 after
  /// Taubin steps, 0.4 after bilateral filtering (which leaves about a quarter of the noise).
  /// Each is the best multiple measured on fandisk, anchor_dense, couplingdown and
  /// mech-holes-shark (libcgal-demo) with Gaussian noise of 0.3% of the diagonal. > 0.
  std::optional<double> noise_tolerance_factor;
  /// Snaps to average (bagging, Breiman 1996): each round snaps the vertices onto the level of
  /// this many hierarchies and moves them to the mean of those snaps. The first hierarchy is the
  /// round's own, built on the segmented copy of mesh(); each further one is built on the
  /// segmented copy (smoothed the same way) of mesh() with every coordinate moved by Gaussian
  /// noise of ensemble_jitter × estimate_noise(mesh()), and cut by the same rule
  /// (Denoiser::snap with a LevelSelector); every snap moves mesh()'s own positions. The greedy
  /// merge order is unstable under noise: the borders of blends and small fillets move with the
  /// noise, so each hierarchy misplaces other faces, and the mean keeps what the snaps agree on.
  /// Fandisk with Gaussian noise of 0.3% of the diagonal along the normals, bilateral copy, five
  /// noise draws, 16 members: RMS distance to the clean mesh 5.21x to 5.53x lower at the
  /// automatic level (mean 5.35x, against 4.25x with one), 4.95x to 5.45x at the best of
  /// K = 20, 30, 40, 60 (mean 5.17x, against 4.06x), Hausdorff distance 0.0092 → 0.0062; with a
  /// jitter of 0.5, 9 members 5.28x and 32 members 5.38x at the automatic level. It costs one
  /// smoothing, one hierarchy and one snap per member; with two threads or more (hierarchy.threads)
  /// two members' copies and hierarchies are made at once, each on one thread, beside the snaps
  /// (fandisk, 16 members: 2.13 s on one thread, 1.31 s on two), for the same result. The mean of
  /// snaps that each keep every triangle's orientation may invert one: such a triangle's vertices
  /// take the first hierarchy's snap (SnapReport::reverted). The level reports (snapped_level) are
  /// the first hierarchy's, and the vertices are no longer exactly on its primitives. 1 (no
  /// ensemble) to 64; AllIncident mode only (a stylized vertex belongs on one primitive, not
  /// between several).
  int ensemble_members = 1;
  /// The jitter of the ensemble's further members, in estimated noise deviations per coordinate,
  /// added before the segmented copy is smoothed: a partial new draw of the noise, which changes
  /// the greedy order without making the copy worse. Fandisk as above, 16 members, automatic
  /// level: 0.3 5.35x, 0.5 5.30x, 0.7 5.24x. In (0, 1].
  double ensemble_jitter = 0.3;
  /// Gauss–Newton steps for curved primitives (a plane-only system converges in one).
  int max_solver_steps = 20;
  /// Hierarchy options used to segment the mesh at each iteration.
  HierarchyOptions hierarchy;
};

/// Throws InvalidInputError if options are out of range.
void validate(const DenoiseOptions& options);

/// Chooses the level of a hierarchy to snap onto (by count, tolerance, or any other rule).
using LevelSelector = std::function<Segmentation(const Hierarchy&)>;
/// The level with `clusters` clusters (cut_by_count).
LevelSelector level_by_count(std::uint32_t clusters);
/// The coarsest level within an RMS `tolerance`, input units (cut_by_tolerance).
LevelSelector level_by_tolerance(double tolerance);

/// RMS distance, input units, by which bilateral smoothing with `options` moves the vertices of
/// `mesh`: an estimate of the standard deviation of noise along the normals (fandisk with
/// Gaussian noise of σ = 0.3% of its diagonal: 0.98 σ). On a noise-free mesh it measures what
/// smoothing does to its edges and is small. Throws InvalidInputError as bilateral_smooth().
double estimate_noise(const Mesh& mesh, const BilateralSmoothingOptions& options = {});

/// A jump of the error curve is the automatic level of a denoising round only when each of its
/// clusters fits its primitive within this many noise tolerances (RMS estimates): a cluster that
/// fits worse straddles two surfaces (Denoiser::automatic_level).
inline constexpr double kMaxJumpClusterRmsInTolerances = 4.5;

/// The automatic level of a denoising round (Denoiser::automatic_level), and how it was chosen.
struct DenoiseLevel {
  Segmentation segmentation;
  /// choose_level() on the hierarchy: its Jump level is kept when its clusters fit the noise.
  AutoLevel automatic;
  /// True when the noise rule chose (no significant jump, or one whose clusters do not fit
  /// within kMaxJumpClusterRmsInTolerances): the tolerance cut below.
  bool by_noise = false;
  /// estimate_noise() of the mesh being denoised, input units (0 in NearestIncident mode).
  double noise = 0;
  double tolerance = 0;  ///< noise × the tolerance factor, input units (0 in NearestIncident mode)
  /// With a Jump level (and not NearestIncident): the largest RMS distance estimate of its
  /// clusters (Hierarchy::rms_estimate), input units: the jump is kept when it is within
  /// kMaxJumpClusterRmsInTolerances × `tolerance`. 0 without a jump.
  double jump_worst_rms = 0;
};

/// What one snapping pass did.
struct SnapReport {
  /// Clusters the vertices were snapped onto: the level's, less any that relabelling emptied.
  std::uint32_t clusters = 0;
  std::uint32_t interior_vertices = 0;  ///< vertices of one cluster only
  std::uint32_t boundary_vertices = 0;  ///< vertices shared by two or more clusters
  /// Vertices placed onto their target (all but the blocked ones and those of no triangle).
  std::uint32_t snapped = 0;
  /// Snapped vertices whose position changed: a vertex already on its target is not counted.
  std::uint32_t moved = 0;
  /// Boundary vertices that were snapped onto fewer primitives than incident ones because the
  /// full move broke a safeguard.
  std::uint32_t fallbacks = 0;
  /// Vertices left where they were: every candidate move was too long or inverted a triangle.
  std::uint32_t blocked = 0;
  double mean_move = 0;  ///< over moved vertices, input units (0 when none moved)
  double max_move = 0;   ///< input units
  /// Hierarchies whose snaps were averaged (DenoiseOptions::ensemble_members; 1 without an
  /// ensemble). The counts above but `moved` and the moves are the first hierarchy's snap's.
  std::uint32_t ensemble_members = 1;
  /// Vertices given the first hierarchy's snap instead of the mean, which inverted one of their
  /// triangles (0 without an ensemble).
  std::uint32_t reverted = 0;
};

/// The clusters a snap moved the vertices onto (Denoiser::snapped_level): the level it was given,
/// after relabelling (DenoiseOptions::relabel_passes), with each cluster's primitive after the
/// robust refit and the relations. Their borders on the denoised mesh,
/// `cluster_borders(denoiser.mesh(), level.labels, primitives)`, are its recovered feature lines.
struct SnappedLevel {
  /// Cluster of each input face, shape (F), 0..K−1, numbered like Segmentation's by decreasing
  /// area (before the snap), ties by lowest face. A cluster relabelling emptied is gone.
  std::vector<std::uint32_t> labels;
  /// One per cluster, in label order, shape (K). `primitive`: what the cluster's vertices were
  /// snapped onto, input units; `algebraic`: the fit the refit started from (describe_clusters()'s
  /// of the level's cluster it came from), and `node` that cluster's tree node. `area` (input
  /// units²), `face_count`, and `rms` and `max`: distances to `primitive` of the cluster's vertices
  /// before the snap, each weighted by the area of its triangles in the cluster (as the hierarchy's
  /// area weights do; `max` leaves out vertices of zero weight), input units: what the snap took
  /// out.
  std::vector<ClusterReport> clusters;
  /// The relations made exact, ordered by kind (parallel first), then by their clusters.
  std::vector<ClusterRelation> relations;
};

/// Step-by-step denoising of one mesh. The vertex and face order never change; only positions do.
class Denoiser {
 public:
  /// Throws InvalidInputError for invalid options or a mesh that fails Mesh::validate().
  explicit Denoiser(Mesh mesh, DenoiseOptions options = {});

  /// One iteration: builds the hierarchy of the current mesh, cuts it with `level` and snaps
  /// (with the ensemble, when DenoiseOptions::ensemble_members > 1).
  SnapReport iterate(const LevelSelector& level);

  /// Snaps the current positions onto a segmentation of the current mesh. `hierarchy` must have
  /// been built on a mesh with the same vertices and triangles as mesh(), with these positions or
  /// others (a smoothed copy); its primitives are refitted on mesh()'s positions unless
  /// refit_outlier_threshold is 0. Throws InvalidInputError when the connectivity differs.
  SnapReport snap(const Hierarchy& hierarchy, const Segmentation& segmentation);

  /// snap(hierarchy, segmentation) and, with DenoiseOptions::ensemble_members > 1, the ensemble:
  /// each further hierarchy is built (with `hierarchy`'s options) on the segmented copy of a
  /// jittered mesh() (smoothed as segmented_mesh() is) and cut by `level`, the current positions
  /// are snapped onto that cut, and the vertices move to the mean of all the snaps. `segmentation`
  /// is the caller's cut of `hierarchy`, normally level(hierarchy); `level` is called once per
  /// further member. The result does not depend on the number of threads. Throws as snap(); when
  /// `level` throws, the positions are put back as they were and snapped_level() is empty.
  SnapReport snap(const Hierarchy& hierarchy, const Segmentation& segmentation,
                  const LevelSelector& level);

  /// The mesh the next iteration segments: mesh(), smoothed when smoothing_steps > 0 or
  /// bilateral_smoothing is set.
  std::shared_ptr<const Mesh> segmented_mesh() const;

  /// `--clusters auto` for denoising. When the hierarchy's error curve has a significant jump
  /// (choose_level's Jump rule: regular parts, chamfers) and every cluster of that level fits its
  /// primitive within 4.5 times the tolerance below (RMS), that level. Otherwise, as under
  /// noise, the tolerance cut (cut_by_tolerance) at noise_tolerance_factor ×
  /// estimate_noise(mesh()): clusters that fit their primitive as well as the noise allows. A
  /// jump with a cluster beyond 4.5 tolerances has merged two surfaces (on the generated noisy
  /// shapes such jumps made the mesh 2 to 7 times farther from the clean shape than its input). The
  /// knee of the curve, the segmentation's fallback, is too coarse to denoise with: on fandisk with
  /// 0.3% noise and bilateral filtering, RMS 3.8x lower against 2.3x at the knee; on
  /// mech-holes-shark 2.1x against 0.4x. `hierarchy` is one built on segmented_mesh() (or on a mesh
  /// with its connectivity). In NearestIncident mode (stylization, which wants few clusters) the
  /// level is always choose_level()'s.
  DenoiseLevel automatic_level(const Hierarchy& hierarchy) const;

  /// The factor automatic_level() uses: DenoiseOptions::noise_tolerance_factor, or its default
  /// for the segmented copy.
  double noise_tolerance_factor() const;

  /// The current mesh (the input after the iterations so far).
  const Mesh& mesh() const { return mesh_; }

  /// The clusters the last snap() (or iterate()) moved the vertices onto; empty before the first.
  const SnappedLevel& snapped_level() const { return snapped_level_; }

 private:
  // snap()'s primitives: the hierarchy's fits of `level`'s clusters refitted on their vertices,
  // the faces relabelled into `labelled`, the relations made exact; sets snapped_level_.
  std::vector<Primitive> snap_primitives(const Hierarchy& hierarchy, const Segmentation& level,
                                         Segmentation& labelled);
  // Moves every vertex onto the primitives of its clusters in `labelled`, within the safeguards.
  // The report's cluster count is left to the caller.
  SnapReport move_vertices(const Segmentation& labelled, const std::vector<Primitive>& primitives);
  // The clusters of v's triangles in `labelled`, nearest primitive to `position` first: the
  // targets of a snap, most preferred first, down to the nearest alone.
  void incident_clusters(std::uint32_t v, const Segmentation& labelled,
                         const std::vector<Primitive>& primitives, const Vec3& position,
                         std::vector<std::uint32_t>& clusters) const;
  // True when moving v to `target` inverts none of its triangles (against the input's
  // orientation; a triangle flattened to zero area is allowed).
  bool keeps_orientation(std::uint32_t v, const Vec3& target) const;
  void refit(const Segmentation& segmentation, std::vector<Primitive>& primitives) const;
  // The snap's clusters (snapped_level) on the current positions, before they move.
  // `points` and `weights` are cluster_vertices() of `relabelled`.
  SnappedLevel describe_snap(const Segmentation& hierarchy_level, const Segmentation& relabelled,
                             const std::vector<std::vector<Vec3>>& points,
                             const std::vector<std::vector<double>>& weights,
                             const std::vector<Primitive>& hierarchy_fits,
                             const std::vector<Primitive>& primitives,
                             std::vector<ClusterRelation> relations) const;
  void cluster_vertices(const Segmentation& segmentation, std::size_t cluster_count,
                        std::vector<std::vector<Vec3>>& points,
                        std::vector<std::vector<double>>& weights) const;
  // Makes the relations the fits agree with exact (DenoiseOptions::relation_significance), from
  // each cluster's vertices (cluster_vertices()), and returns them on the clusters' labels.
  std::vector<ClusterRelation> regularize(const std::vector<std::vector<Vec3>>& points,
                                          const std::vector<std::vector<double>>& weights,
                                          std::vector<Primitive>& primitives) const;
  // Moves faces to the nearest primitive of their neighbourhood, judged on `judged`'s positions
  // (see DenoiseOptions::relabel_passes), and refits.
  void relabel(const Mesh& judged, std::vector<Primitive>& primitives,
               Segmentation& segmentation) const;

  // The copy of `mesh` (mesh_'s connectivity, any positions) that a round segments: smoothed as
  // the options ask, or as it is; on `threads` threads (0: the options'). Reads nothing of mesh_
  // that snaps change, so that the ensemble's members run it while the caller snaps.
  std::shared_ptr<const Mesh> segmented_copy(const Mesh& mesh, unsigned threads = 0) const;
  // bilateral_smooth(mesh_) with the noise estimate's options: estimate_noise's copy, and the
  // segmented copy too when DenoiseOptions::bilateral_smoothing has those options (up to
  // threads), so that a round smooths the mesh once, not twice.
  std::shared_ptr<const Mesh> estimate_copy() const;

  // estimate_copy()'s result for the current positions (null until asked, reset by snap()),
  // guarded by its mutex since the const methods that fill it may run concurrently. Copied and
  // moved with the Denoiser (the copy is immutable and shared), each with its own mutex.
  struct EstimateCopyCache {
    EstimateCopyCache() = default;
    EstimateCopyCache(const EstimateCopyCache& other) : copy(other.get()) {}
    EstimateCopyCache& operator=(const EstimateCopyCache& other) {
      if (this != &other) set(other.get());
      return *this;
    }
    std::shared_ptr<const Mesh> get() const {
      const std::lock_guard lock(mutex);
      return copy;
    }
    void set(std::shared_ptr<const Mesh> mesh) {
      const std::lock_guard lock(mutex);
      copy = std::move(mesh);
    }
    mutable std::mutex mutex;
    std::shared_ptr<const Mesh> copy;
  };

  Mesh mesh_;
  DenoiseOptions options_;
  mutable EstimateCopyCache estimate_copy_;
  SnappedLevel snapped_level_;
  std::vector<Vec3> input_normals_;        // per triangle, unnormalised: orientation reference
  std::vector<double> local_edge_length_;  // per vertex, in the input mesh
  // Triangles around each vertex: those of vertex v are
  // vertex_triangles_[vertex_triangle_offsets_[v] .. vertex_triangle_offsets_[v + 1]).
  std::vector<std::uint32_t> vertex_triangle_offsets_;
  std::vector<std::uint32_t> vertex_triangles_;
};

/// One-shot: `iterations` times, segment the mesh, cut with `level`, snap. Throws
/// InvalidInputError for iterations < 1, and as Denoiser.
Mesh denoise(const Mesh& mesh, const LevelSelector& level, const DenoiseOptions& options = {},
             int iterations = 1);

}  // namespace primseg
