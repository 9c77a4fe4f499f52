// primseg view: one self-contained HTML page to browse the whole hierarchy in a browser.
//
// The page gets the mesh and the merge tree as little-endian typed arrays in base64 (the layout
// is documented by their reader, web/src/data.js), and cuts levels itself. It also gets the
// automatic levels (auto_level.hpp); with --skeleton, the skeleton of one level and its skin
// weights, which it poses itself as primseg deform does; with --regularize, the relations of
// every coarse level (relations.hpp) and the fits they make exact.

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>

#include "../src/file_io.hpp"
#include "../src/parallel.hpp"
#include "command.hpp"
#include "limits.hpp"
#include "primseg/auto_level.hpp"
#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/relations.hpp"
#include "primseg/skeleton.hpp"
#include "primseg/skinning.hpp"
#include "primseg/tree_io.hpp"
#include "skeleton_outputs.hpp"
#include "viewer_bundle.hpp"

namespace primseg::cli {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the page reads the arrays as little-endian typed arrays");

/// The page carries the refined primitive and exact errors of every cluster of every level of
/// at most this many clusters (at most twice as many nodes). Finer levels show their clusters'
/// type and RMS estimate only (a 1M-face page would otherwise carry 180 MB of them).
constexpr std::uint32_t kMaxClustersWithParameters = 16385;
/// --regularize: the relations of every level of up to this many clusters, or up to the level the
/// page opens at if it is finer, up to kMaxDefaultRelationClusters (each level costs about a cut
/// --regularize of the whole mesh).
constexpr std::uint32_t kRelationClusters = 100;
constexpr std::uint32_t kMaxDefaultRelationClusters = 1000;
static_assert(kRelationClusters <= kMaxDefaultRelationClusters &&
              kMaxDefaultRelationClusters <= kMaxClustersWithParameters);

std::string base64(const void* data, std::size_t size) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* bytes = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= size; i += 3) {
    const unsigned v = bytes[i] << 16 | bytes[i + 1] << 8 | bytes[i + 2];
    out += kAlphabet[v >> 18];
    out += kAlphabet[v >> 12 & 63];
    out += kAlphabet[v >> 6 & 63];
    out += kAlphabet[v & 63];
  }
  if (i < size) {
    const unsigned v = bytes[i] << 16 | (i + 1 < size ? bytes[i + 1] << 8 : 0);
    out += kAlphabet[v >> 18];
    out += kAlphabet[v >> 12 & 63];
    out += i + 1 < size ? kAlphabet[v >> 6 & 63] : '=';
    out += '=';
  }
  return out;
}

/// Appends `<script type="application/octet-stream" id="primseg-NAME">BASE64</script>`.
template <typename T>
void append_array(std::string& html, const char* name, const std::vector<T>& values) {
  html += "<script type=\"application/octet-stream\" id=\"primseg-";
  html += name;
  html += "\">";
  html += base64(values.data(), values.size() * sizeof(T));
  html += "</script>\n";
}

/// JSON that can sit inside a <script> element: no "</script" can appear.
std::string script_safe(const nlohmann::json& json) {
  const std::string text = json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '<')
      out += "\\u003c";  // '<' only occurs inside JSON strings, where the escape is valid
    else
      out += c;
  }
  return out;
}

/// The skeleton shown over the mesh (--skeleton) and its skin weights.
struct PageSkeleton {
  Skeleton skeleton;
  SkinWeights weights;
  double band = 0;
};

/// Compressed rows of a list of lists: (offsets of shape n + 1, values).
template <typename Item, typename Member>
std::pair<std::vector<std::uint32_t>, std::vector<std::uint32_t>> compressed_rows(
    const std::vector<Item>& items, Member member) {
  std::vector<std::uint32_t> offsets{0}, values;
  for (const Item& item : items) {
    const auto& row = item.*member;
    values.insert(values.end(), row.begin(), row.end());
    offsets.push_back(static_cast<std::uint32_t>(values.size()));
  }
  return {std::move(offsets), std::move(values)};
}

/// The skeleton's header entry and arrays (layout in web/src/data.js). Positions are absolute
/// doubles here: the page poses the mesh as primseg deform does, to round-off.
nlohmann::json append_skeleton(std::string& html, const Mesh& mesh, const PageSkeleton& page) {
  const Skeleton& skeleton = page.skeleton;
  std::vector<double> rest(mesh.positions.size() * 3);
  for (std::size_t v = 0; v < mesh.positions.size(); ++v)
    std::copy(mesh.positions[v].begin(), mesh.positions[v].end(), rest.begin() + 3 * v);
  std::vector<double> joint_positions;
  std::vector<std::uint8_t> joint_kinds, joint_visible, bone_visible;
  for (const Joint& joint : skeleton.joints) {
    joint_positions.insert(joint_positions.end(), joint.position.begin(), joint.position.end());
    joint_kinds.push_back(static_cast<std::uint8_t>(joint.kind));
    joint_visible.push_back(joint.visible ? 1 : 0);
  }
  std::vector<double> bone_points;
  for (const Bone& bone : skeleton.bones) {
    bone_points.insert(bone_points.end(), bone.point.begin(), bone.point.end());
    bone_visible.push_back(bone.visible ? 1 : 0);
  }
  const auto [joint_bone_offsets, joint_bones] = compressed_rows(skeleton.joints, &Joint::bones);
  const auto [bone_joint_offsets, bone_joints] = compressed_rows(skeleton.bones, &Bone::joints);
  const BoneTree tree = bone_tree(skeleton);
  append_array(html, "skeleton-rest", rest);
  append_array(html, "skeleton-joint-positions", joint_positions);
  append_array(html, "skeleton-joint-kinds", joint_kinds);
  append_array(html, "skeleton-joint-visible", joint_visible);
  append_array(html, "skeleton-joint-bone-offsets", joint_bone_offsets);
  append_array(html, "skeleton-joint-bones", joint_bones);
  append_array(html, "skeleton-bone-joint-offsets", bone_joint_offsets);
  append_array(html, "skeleton-bone-joints", bone_joints);
  append_array(html, "skeleton-bone-points", bone_points);
  append_array(html, "skeleton-bone-visible", bone_visible);
  append_array(html, "skeleton-bone-order", tree.order);
  append_array(html, "skeleton-bone-parent-joint", tree.parent_joint);
  append_array(html, "skeleton-bone-parent-bone", tree.parent_bone);
  append_array(html, "skeleton-weight-offsets", page.weights.offsets);
  append_array(html, "skeleton-weight-bones", page.weights.bones);
  append_array(html, "skeleton-weight-values", page.weights.weights);
  append_array(html, "skeleton-face-labels", skeleton.face_labels);
  return {{"clusters", skeleton.cluster_count()},
          {"joints", skeleton.joints.size()},
          {"rootBone", skeleton.root_bone()},
          {"band", page.band}};
}

/// Appends a report's primitive (9 values: point relative to `center`, axis, radius,
/// minor_radius, half_angle) and its errors (rms, max), as the page reads them.
void append_fit(const ClusterReport& report, const Vec3& center, std::vector<double>& parameters,
                std::vector<double>& errors) {
  const Primitive& p = report.primitive;
  for (int a = 0; a < 3; ++a) parameters.push_back(p.point[a] - center[a]);
  for (int a = 0; a < 3; ++a) parameters.push_back(p.axis[a]);
  parameters.push_back(p.radius);
  parameters.push_back(p.minor_radius);
  parameters.push_back(p.half_angle);
  errors.push_back(report.rms);
  errors.push_back(report.max);
}

/// Whether `node` is a cluster of a level of at most `merges` more clusters than components: its
/// parent is one of the last `merges` real merges, a trailing merge or none (component roots).
bool is_cluster_of_a_level(const Hierarchy& hierarchy, std::uint32_t node, std::uint32_t merges) {
  const std::uint32_t f = hierarchy.face_count();
  const std::uint32_t real = f - hierarchy.component_count();
  const std::uint32_t parent = hierarchy.parents()[node];
  return parent == std::numeric_limits<std::uint32_t>::max() ||
         parent - f >= real - std::min(real, merges);
}

/// The relations of one level and the fits they changed.
struct LevelRelations {
  std::vector<ClusterRelation> relations;
  std::vector<std::uint32_t> nodes;  ///< tree node of each cluster label, shape (K)
  /// The reports of the relations' clusters after regularize_clusters(), with their nodes, by
  /// increasing node (the page looks them up by node).
  std::vector<std::pair<std::uint32_t, ClusterReport>> fits;
};

/// The relations `cut --clusters K --regularize` finds, for every level K from the fewest
/// clusters to `max_clusters`, and the fits they make exact (layout in web/src/data.js).
/// `carried` (increasing) and `reports` are the nodes the page carries and their reports, which
/// include every cluster of these levels. Levels run on `threads` threads; each is the same as
/// on one.
nlohmann::json append_relations(std::string& html, const Hierarchy& hierarchy,
                                const std::vector<std::uint32_t>& carried,
                                const std::vector<ClusterReport>& reports,
                                std::uint32_t max_clusters, const RelationOptions& options,
                                const Vec3& center, unsigned threads) {
  const std::uint32_t first = hierarchy.component_count();
  const std::uint32_t last = std::min(max_clusters, hierarchy.face_count());
  const std::uint32_t level_count = last >= first ? last - first + 1 : 0;
  std::vector<LevelRelations> levels(level_count);
  // The clusters of these levels alone.
  std::vector<std::uint32_t> level_nodes;
  std::vector<ClusterReport> level_reports;
  for (std::size_t i = 0; i < carried.size(); ++i)
    if (is_cluster_of_a_level(hierarchy, carried[i], last - std::min(last, first))) {
      level_nodes.push_back(carried[i]);
      level_reports.push_back(reports[i]);
    }
  const LevelRegularizer regularizer(hierarchy, level_nodes, level_reports, options, threads);
  detail::parallel_for_threads(
      level_count, detail::thread_count(threads), [&](std::size_t i, unsigned) {
        LevelRelations& level = levels[i];
        RegularizedLevel regularized = regularizer.level(first + static_cast<std::uint32_t>(i));
        level.relations = std::move(regularized.relations);
        std::vector<bool> member(regularized.nodes.size(), false);
        for (const ClusterRelation& relation : level.relations) {
          for (const std::uint32_t c : relation.clusters) member[c] = true;
          for (const std::uint32_t c : relation.orthogonal_to) member[c] = true;
        }
        for (std::size_t c = 0; c < regularized.nodes.size(); ++c)
          if (member[c]) level.fits.emplace_back(regularized.nodes[c], regularized.reports[c]);
        std::sort(level.fits.begin(), level.fits.end(),
                  [](const auto& a, const auto& b) { return a.first < b.first; });
        level.nodes = std::move(regularized.nodes);
      });

  std::vector<std::uint32_t> level_offsets{0}, member_offsets{0}, members, first_side;
  std::vector<std::uint8_t> kinds;
  std::vector<std::uint32_t> fit_offsets{0}, fit_nodes;
  std::vector<double> deviations, parameters, errors;
  for (const LevelRelations& level : levels) {
    for (const ClusterRelation& relation : level.relations) {
      kinds.push_back(static_cast<std::uint8_t>(relation.kind));
      for (const std::uint32_t c : relation.clusters) members.push_back(level.nodes[c]);
      for (const std::uint32_t c : relation.orthogonal_to) members.push_back(level.nodes[c]);
      first_side.push_back(static_cast<std::uint32_t>(relation.clusters.size()));
      member_offsets.push_back(static_cast<std::uint32_t>(members.size()));
      deviations.push_back(relation.deviation);
    }
    level_offsets.push_back(static_cast<std::uint32_t>(kinds.size()));
    for (const auto& [node, report] : level.fits) {
      fit_nodes.push_back(node);
      append_fit(report, center, parameters, errors);
    }
    fit_offsets.push_back(static_cast<std::uint32_t>(fit_nodes.size()));
  }
  append_array(html, "relations-level-offsets", level_offsets);
  append_array(html, "relations-kinds", kinds);
  append_array(html, "relations-member-offsets", member_offsets);
  append_array(html, "relations-members", members);
  append_array(html, "relations-first-side", first_side);
  append_array(html, "relations-deviations", deviations);
  append_array(html, "relations-fit-offsets", fit_offsets);
  append_array(html, "relations-fit-nodes", fit_nodes);
  append_array(html, "relations-fit-parameters", parameters);
  append_array(html, "relations-fit-errors", errors);
  nlohmann::json kind_names = nlohmann::json::array();
  for (const auto kind : {ClusterRelation::Kind::Parallel, ClusterRelation::Kind::Coaxial,
                          ClusterRelation::Kind::Orthogonal, ClusterRelation::Kind::EqualRadius,
                          ClusterRelation::Kind::Coplanar, ClusterRelation::Kind::Tangent,
                          ClusterRelation::Kind::Concentric})
    kind_names.push_back(to_string(kind));
  return {{"firstClusters", first},
          {"levels", level_count},
          {"relations", kinds.size()},
          {"fits", fit_nodes.size()},
          {"kinds", std::move(kind_names)}};
}

/// The mesh as the page draws it: positions (float32, relative to `center`) and triangles.
void append_mesh_arrays(std::string& html, const Mesh& mesh, const Vec3& center) {
  std::vector<float> positions(mesh.positions.size() * 3);
  for (std::size_t v = 0; v < mesh.positions.size(); ++v)
    for (int a = 0; a < 3; ++a)
      positions[3 * v + a] = static_cast<float>(mesh.positions[v][a] - center[a]);
  std::vector<std::uint32_t> triangles(mesh.triangles.size() * 3);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    std::copy(mesh.triangles[t].begin(), mesh.triangles[t].end(), triangles.begin() + 3 * t);
  append_array(html, "positions", positions);
  append_array(html, "triangles", triangles);
  // Input faces of the triangles: only needed for polygon meshes (else the identity).
  if (mesh.triangle_count() != mesh.face_count())
    append_array(html, "face-of-triangle", mesh.face_of_triangle);
}

/// The tree as the page browses it: each merge's children, RMS estimate and primitive type.
void append_tree_arrays(std::string& html, const Hierarchy& hierarchy) {
  const std::uint32_t f = hierarchy.face_count();
  const auto merges = hierarchy.merges();
  std::vector<std::uint32_t> children(merges.size() * 2);
  std::vector<double> rms(merges.size());
  std::vector<std::uint8_t> types(merges.size());
  for (std::size_t i = 0; i < merges.size(); ++i) {
    children[2 * i] = merges[i].first;
    children[2 * i + 1] = merges[i].second;
    rms[i] = hierarchy.rms_estimate(static_cast<std::uint32_t>(f + i));
    types[i] = static_cast<std::uint8_t>(merges[i].primitive.type);
  }
  append_array(html, "children", children);
  append_array(html, "rms", rms);
  append_array(html, "types", types);
}

/// The clusters of the levels of at most kMaxClustersWithParameters clusters: the nodes whose
/// parent is one of the last real merges, a trailing merge or none (component roots).
std::vector<std::uint32_t> parameter_nodes(const Hierarchy& hierarchy) {
  const std::uint32_t f = hierarchy.face_count();
  const std::uint32_t real = f - hierarchy.component_count();
  const std::uint32_t components = hierarchy.component_count();
  std::vector<std::uint32_t> carried;
  if (components > kMaxClustersWithParameters) return carried;
  const std::uint32_t carried_merges = std::min(real, kMaxClustersWithParameters - components);
  for (std::uint32_t node = 0; node < f + real; ++node)
    if (is_cluster_of_a_level(hierarchy, node, carried_merges)) carried.push_back(node);
  return carried;
}

/// The page's data. `fit_seconds`, `relations_seconds`: set to the time the geometric fits and
/// the relations (of the levels of at most `relation_clusters` clusters; 0: none) took.
std::string page_data(const Hierarchy& hierarchy, const std::string& mesh_name,
                      std::uint32_t initial_clusters, const AutoLevel& automatic,
                      const std::optional<PageSkeleton>& skeleton, std::uint32_t relation_clusters,
                      const RelationOptions& relation_options, unsigned threads,
                      double& fit_seconds, double& relations_seconds) {
  const Mesh& mesh = hierarchy.mesh();
  const std::uint32_t f = hierarchy.face_count();
  // Positions relative to the bounding-box centre, so that float32 keeps the shape's detail
  // even far from the origin.
  Vec3 low = mesh.positions.empty() ? Vec3{0, 0, 0} : mesh.positions[0], high = low;
  for (const Vec3& p : mesh.positions)
    for (int a = 0; a < 3; ++a) {
      low[a] = std::min(low[a], p[a]);
      high[a] = std::max(high[a], p[a]);
    }
  const Vec3 center{(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, (low[2] + high[2]) / 2};

  // The parameter nodes' primitives as every cut reports them: the geometric fit and its exact
  // errors.
  const std::vector<std::uint32_t> carried = parameter_nodes(hierarchy);
  DescribeOptions describe;
  describe.threads = threads;
  const auto fit_start = Clock::now();
  const std::vector<ClusterReport> reports = describe_nodes(hierarchy, carried, describe);
  fit_seconds = seconds_since(fit_start);
  std::vector<double> parameters, errors;
  parameters.reserve(carried.size() * 9);
  errors.reserve(carried.size() * 2);
  for (const ClusterReport& r : reports) append_fit(r, center, parameters, errors);
  std::string relation_arrays;
  nlohmann::json relation_header;
  if (relation_clusters > 0) {
    const auto relations_start = Clock::now();
    relation_header = append_relations(relation_arrays, hierarchy, carried, reports,
                                       relation_clusters, relation_options, center, threads);
    relations_seconds = seconds_since(relations_start);
  }

  nlohmann::json header = {
      {"format", 2},
      {"name", mesh_name},
      {"faces", f},
      {"vertices", mesh.vertex_count()},
      {"triangles", mesh.triangle_count()},
      {"components", hierarchy.component_count()},
      {"center", center},
      {"bboxDiagonal", bounding_box_diagonal(mesh)},
      {"weights", hierarchy.options().weights == VertexWeights::Uniform ? "uniform" : "area"},
      {"maxClustersWithParameters", kMaxClustersWithParameters},
      {"initialClusters", initial_clusters},
      {"autoLevel", automatic.clusters},
  };
  // Automatic levels, best score first (as segment --clusters auto lists its candidates).
  nlohmann::json levels = nlohmann::json::array();
  for (const LevelCandidate& c : automatic.candidates)
    levels.push_back({{"clusters", c.clusters},
                      {"rms", c.rms},
                      {"score", c.score},
                      {"mergeScore", c.merge_score}});
  header["levels"] = std::move(levels);
  std::string skeleton_arrays;
  if (skeleton) header["skeleton"] = append_skeleton(skeleton_arrays, mesh, *skeleton);
  if (!relation_header.is_null()) header["relations"] = std::move(relation_header);
  std::string html = "<script type=\"application/json\" id=\"primseg-header\">";
  html += script_safe(header);
  html += "</script>\n";
  append_mesh_arrays(html, mesh, center);
  append_tree_arrays(html, hierarchy);
  append_array(html, "parameter-nodes", carried);
  append_array(html, "parameters", parameters);
  append_array(html, "errors", errors);
  // A polygon face may be non-planar: its own RMS is then not zero.
  if (mesh.triangle_count() != f) {
    std::vector<double> leaf_rms(f);
    for (std::uint32_t face = 0; face < f; ++face) leaf_rms[face] = hierarchy.rms_estimate(face);
    append_array(html, "leaf-rms", leaf_rms);
  }
  return html + skeleton_arrays + relation_arrays;
}

bool same_mesh(const Mesh& a, const Mesh& b) {
  return a.positions == b.positions && a.polygon_offsets == b.polygon_offsets &&
         a.polygon_vertices == b.polygon_vertices;
}

struct ViewCommandOptions {
  std::string mesh_path, output, primitives = "plane,cylinder,sphere";
  std::optional<std::string> tree_path;
  std::optional<std::string> clusters;  // K or auto
  bool skeleton = false;
  std::optional<std::string> skeleton_clusters;  // K or auto; default: the page's level
  bool regularize = false;
  std::optional<std::uint32_t> regularize_clusters;  // default: kRelationClusters
  RelationChoice relations;
  double band = SkinningOptions{}.band;
  std::string joints{to_string(SkeletonOptions{}.joints)};
  unsigned threads = 0;
  bool quiet = false;
  ResourceLimits limits;
};
// The viewer page embedded at build time and the position of its data marker, or
// InvalidInputError when this primseg was built without it.
std::pair<std::string_view, std::size_t> viewer_page() {
  const std::string_view page = viewer_template();
  const std::size_t marker = page.find(kViewerDataMarker);
  if (page.empty() || marker == std::string_view::npos)
    throw InvalidInputError(
        "view: this primseg was built without the web viewer (npm was not available). To enable "
        "it: cd web && npm ci, then configure and build primseg again (CMake bundles web/ with "
        "esbuild and embeds the page)");
  return {page, marker};
}

// The hierarchy of `mesh`: built, or read from --tree and checked to be that mesh's.
Hierarchy view_hierarchy(const ViewCommandOptions& o, const std::shared_ptr<const Mesh>& mesh,
                         const HierarchyOptions& options) {
  if (!o.tree_path) return HierarchyBuilder(mesh, options).finish(Progress("hierarchy", o.quiet));
  Hierarchy tree = read_input_tree(*o.tree_path, nullptr, o.limits.max_memory);
  if (!same_mesh(tree.mesh(), *mesh))
    throw InvalidInputError("view: the tree from " + input_name(*o.tree_path) +
                            " was not built from " + input_name(o.mesh_path));
  return tree;
}

// The skeleton the page draws: of --skeleton-clusters' level, else of the level it opens at.
PageSkeleton page_skeleton(const ViewCommandOptions& o, const SkeletonOptions& rule,
                           const SkinningOptions& skinning, const Mesh& mesh,
                           const Hierarchy& hierarchy, const Segmentation& opening_level) {
  const Segmentation bones = o.skeleton_clusters
                                 ? cut(hierarchy, {o.skeleton_clusters, std::nullopt}).segmentation
                                 : opening_level;
  Skeleton extracted = extract_skeleton(hierarchy, bones, rule);
  SkinWeights weights = compute_skin_weights(mesh, extracted, skinning);
  return PageSkeleton{std::move(extracted), std::move(weights), skinning.band};
}

// Runs `primseg view` with its parsed options.
void run_view(const ViewCommandOptions& o) {
  HierarchyOptions options;
  options.primitives = parse_primitives(o.primitives);
  options.threads = o.threads;
  validate(options);
  validate_relation_options(o.relations);
  if (o.tree_path == kStandardInput && o.mesh_path == kStandardInput)
    throw InvalidInputError("view: only one of MESH and --tree can be standard input ('-')");
  const SkeletonOptions joint_rule = skeleton_options(o.joints);
  const SkinningOptions skinning = skinning_options(o.band);
  const auto [page, marker] = viewer_page();
  auto mesh =
      std::make_shared<const Mesh>(read_geometry_within(o.mesh_path, o.limits, kViewerPageBytes));
  if (o.clusters) validate_level({o.clusters, std::nullopt}, mesh->face_count());
  if (o.skeleton_clusters) validate_level({o.skeleton_clusters, std::nullopt}, mesh->face_count());
  const auto build_start = Clock::now();
  const Hierarchy hierarchy = view_hierarchy(o, mesh, options);
  const double build_seconds = seconds_since(build_start);
  const ChosenLevel level = cut(hierarchy, {o.clusters, std::nullopt});
  const std::uint32_t initial = level.segmentation.cluster_count();
  const AutoLevel automatic = level.automatic ? *level.automatic : choose_level(hierarchy);
  std::optional<PageSkeleton> skeleton;
  if (o.skeleton || o.skeleton_clusters)
    skeleton = page_skeleton(o, joint_rule, skinning, *mesh, hierarchy, level.segmentation);
  const std::uint32_t relation_clusters =
      o.regularize_clusters
          ? *o.regularize_clusters
          : (o.regularize ? std::clamp(initial, kRelationClusters, kMaxDefaultRelationClusters)
                          : 0);
  std::string html(page.substr(0, marker));
  double fit_seconds = 0, relations_seconds = 0;
  html += page_data(hierarchy, input_name(std::filesystem::path(o.mesh_path).filename()), initial,
                    automatic, skeleton, relation_clusters, o.relations.for_mesh(hierarchy.mesh()),
                    o.threads, fit_seconds, relations_seconds);
  html += page.substr(marker + kViewerDataMarker.size());
  detail::write_file_atomically(o.output, html);
  if (o.quiet) return;
  const std::string bones =
      skeleton ? ", skeleton of " + count_of(skeleton->skeleton.cluster_count(), "bone") : "";
  char relations[96] = "";
  if (relation_clusters > 0)
    std::snprintf(relations, sizeof relations,
                  ", relations of the levels of up to %u clusters in %.3f s",
                  std::min(relation_clusters, mesh->face_count()), relations_seconds);
  std::printf(
      "%s: %s, hierarchy %s in %.3f s, geometric fits in %.3f s%s; %s: %.1f MB, opens at %s "
      "(automatic level %u)%s\n",
      input_name(o.mesh_path).c_str(), count_of(mesh->face_count(), "face").c_str(),
      o.tree_path ? "read" : "built", build_seconds, fit_seconds, relations, o.output.c_str(),
      static_cast<double>(html.size()) / 1e6, count_of(initial, "cluster").c_str(),
      automatic.clusters, bones.c_str());
}

}  // namespace

Command add_view_command(CLI::App& app) {
  auto o = std::make_shared<ViewCommandOptions>();
  auto* view = app.add_subcommand(
      "view", "Write a self-contained HTML page to browse the whole hierarchy in a browser");
  view->add_option("MESH", o->mesh_path, "Input mesh (.off .obj .ply .stl; - for standard input)")
      ->required();
  view->add_option("--tree", o->tree_path,
                   "Hierarchy written by segment --tree for this mesh (else it is built; - for "
                   "standard input)");
  view->add_option("--clusters", o->clusters,
                   std::string("Level shown when the page opens (default: the --tolerance ") +
                       kDefaultTolerance + " level)");
  view->add_option("-o,--output", o->output, "The HTML page to write")->required();
  view->add_flag("--skeleton", o->skeleton,
                 "Draw the skeleton of a level (primseg skeleton) with draggable joints that pose "
                 "the mesh (primseg deform)");
  view->add_option("--skeleton-clusters", o->skeleton_clusters,
                   "Level of the skeleton: K or auto (default: the level the page opens at); "
                   "implies --skeleton");
  view->add_option("--band", o->band,
                   "--skeleton: skinning blend half-width on each side of a boundary, in bone "
                   "radii")
      ->capture_default_str();
  add_joints_option(*view, o->joints, "--skeleton: ");
  view->add_flag("--regularize", o->regularize,
                 "List the relations cut --regularize finds (parallel, orthogonal, coaxial, "
                 "equal radius, coplanar, tangent) at every level of up to --regularize-clusters "
                 "clusters, highlight "
                 "their clusters, and show the fits they make exact");
  view->add_option("--regularize-clusters", o->regularize_clusters,
                   "The levels of --regularize: every level of up to this many clusters (at most " +
                       std::to_string(kMaxClustersWithParameters) + "; default " +
                       std::to_string(kRelationClusters) +
                       ", or the level the page opens at if finer, up to " +
                       std::to_string(kMaxDefaultRelationClusters) + "); implies --regularize")
      ->check(CLI::Range(1u, kMaxClustersWithParameters));
  add_relation_options(*view, o->relations);
  view->add_option("--primitives", o->primitives,
                   "Primitive types when the hierarchy is built, comma-separated")
      ->capture_default_str();
  view->add_option("--threads", o->threads, "Threads when the hierarchy is built (0: all cores)")
      ->capture_default_str();
  view->add_flag("--quiet,-q", o->quiet, "No summary or progress output");
  add_limit_options(*view, o->limits, kViewBytesPerFace);

  return {view, [o] { run_view(*o); }};
}

}  // namespace primseg::cli
