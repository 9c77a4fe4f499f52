// libFuzzer target for what users do with a tree: cluster reports with geometric fits, boundary
// refinement, skeletons and skinning weights, denoising, the mesh distance and pictures, on the
// small grid meshes of grid_mesh.hpp (degenerate, duplicate and non-manifold faces, several
// components).
//
// Each input runs twice: on the decoded mesh and on the same mesh scaled by a power of two.
// Checked:
// - every result is finite, and holds what its header promises: a report's `max` is the largest
//   distance of its cluster's vertices of positive weight and bounds its `rms`; refinement keeps
//   the number of clusters and each one connected; border curves walk their border's edges,
//   angles within [0, 180]; a skeleton has a bone per cluster and valid
//   joint ids; every skinning row sums to 1; its glTF file is well formed (chunk sizes, every
//   accessor inside the buffer, finite bounds, float32 weight rows summing to 1); denoising keeps
//   the connectivity and inverts no triangle; a distance's mean <= RMS <= Hausdorff;
// - units do not matter (mesh.hpp, kMaxCoordinateMagnitude): the scaled run gives the same tree,
//   costs, labels, weights, border curves and angles and picture, and every length scaled by
//   exactly the same power of two (but for round-off zeros that underflowed below the normal
//   doubles, see ScaleCheck);
// - nothing throws but primseg::InvalidInputError where a function documents it.
//
// Input layout: byte 0 = options (bit 0: all five primitive types, bit 1: uniform weights,
// bit 2: denoise on a bilateral copy, bit 3: stylize, bit 4: denoise at the automatic level,
// bits 5-7: the scale's exponent), byte 1 = K (mod F; its top bit also asks, without bit 3, for
// an ensemble of two snaps), then grid_mesh.hpp's layout.

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "grid_mesh.hpp"
#include "primseg/borders.hpp"
#include "primseg/cut.hpp"
#include "primseg/denoise.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_distance.hpp"
#include "primseg/refine.hpp"
#include "primseg/relations.hpp"
#include "primseg/render.hpp"
#include "primseg/skeleton.hpp"
#include "primseg/skeleton_gltf.hpp"
#include "primseg/skinning.hpp"
#include "tree_invariants.hpp"

namespace {

using namespace primseg;

using fuzz::fail;

void check_finite(const Vec3& v, const char* what) {
  for (const double c : v)
    if (!std::isfinite(c)) fail(what, c);
}

void check_length(double x, const char* what) {
  if (!std::isfinite(x) || x < 0) fail(what, x);
}

void check_primitive(const Primitive& p) {
  check_finite(p.point, "primitive point");
  check_finite(p.axis, "primitive axis");
  check_length(p.radius, "primitive radius");
  check_length(p.minor_radius, "primitive minor radius");
  if (!std::isfinite(p.half_angle)) fail("primitive half angle", p.half_angle);
}

struct Settings {
  HierarchyOptions hierarchy;
  DenoiseOptions denoise;
  bool automatic_level = false;
  int exponent = 0;
  std::uint8_t level = 0;
};

Settings decode_settings(std::uint8_t flags, std::uint8_t level) {
  constexpr int kExponents[8] = {1, -1, 3, -5, 20, -20, 100, -100};
  Settings settings;
  settings.hierarchy.threads = 1;
  if (flags & 1)
    settings.hierarchy.primitives = {PrimitiveType::Plane, PrimitiveType::Cylinder,
                                     PrimitiveType::Sphere, PrimitiveType::Cone,
                                     PrimitiveType::Torus};
  if (flags & 2) settings.hierarchy.weights = VertexWeights::Uniform;
  settings.denoise.hierarchy = settings.hierarchy;
  if (flags & 4) {
    BilateralSmoothingOptions bilateral;
    bilateral.threads = 1;
    settings.denoise.bilateral_smoothing = bilateral;
  }
  if (flags & 8)
    settings.denoise.mode = SnapMode::NearestIncident;
  else if (level & 0x80)
    settings.denoise.ensemble_members = 2;
  settings.automatic_level = (flags & 16) != 0;
  settings.exponent = kExponents[flags >> 5];
  settings.level = level;
  return settings;
}

// Everything one run computes.
struct Results {
  std::optional<Hierarchy> hierarchy;
  Segmentation level;
  std::vector<ClusterReport> reports;
  RefinedLevel refined;
  std::vector<ClusterBorder> borders;
  Skeleton skeleton;
  SkinWeights skin;
  Mesh denoised;
  std::optional<MeshDistance> distance;
  std::vector<std::uint8_t> picture;
};

Vec3 triangle_normal(const Mesh& mesh, const Triangle& t) {
  const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}

double norm(const Vec3& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

void check_reports(const Hierarchy& hierarchy, const Segmentation& level,
                   const std::vector<ClusterReport>& reports) {
  const Mesh& mesh = hierarchy.mesh();
  const DualGraph& graph = hierarchy.graph();
  if (reports.size() != level.cluster_count()) fail("report count", double(reports.size()));
  std::vector<double> largest(reports.size(), 0);
  std::vector<std::uint32_t> faces(reports.size(), 0);
  const double diagonal = bounding_box_diagonal(mesh);
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const std::uint32_t label = level.labels[mesh.face_of_triangle[t]];
    const Triangle corners = graph.corners(t);
    const std::array<double, 3> weights = graph.corner_weights(t);
    for (int k = 0; k < 3; ++k)
      if (weights[k] > 0)
        largest[label] =
            std::max(largest[label], reports[label].primitive.distance(mesh.positions[corners[k]]));
  }
  for (const std::uint32_t label : level.labels) ++faces[label];
  for (std::size_t c = 0; c < reports.size(); ++c) {
    const ClusterReport& report = reports[c];
    check_primitive(report.primitive);
    check_primitive(report.algebraic);
    check_length(report.area, "report area");
    check_length(report.rms, "report rms");
    check_length(report.max, "report max");
    if (report.face_count != faces[c]) fail("report face count", report.face_count, faces[c]);
    // Reports measure in the working frame: equal up to round-off of the mesh's size.
    if (std::abs(report.max - largest[c]) > 1e-9 * largest[c] + 1e-12 * diagonal)
      fail("report max is not the largest distance", report.max, largest[c]);
    if (report.rms > report.max * (1 + 1e-12)) fail("report rms above max", report.rms, report.max);
  }
}

// Each curve walks edges of the mesh, its border's edge count in all, with lengths and angles in
// range.
void check_borders(const Mesh& mesh, const std::vector<ClusterBorder>& borders) {
  for (const ClusterBorder& border : borders) {
    if (!(border.first < border.second)) fail("border clusters", border.first, border.second);
    check_length(border.length, "border length");
    if (!(std::isnan(border.angle) || (border.angle >= 0 && border.angle <= 180)))
      fail("border angle", border.angle);
    std::uint32_t edges = 0;
    for (const BorderCurve& curve : border.curves) {
      if (curve.vertices.size() < 2) fail("border curve size", double(curve.vertices.size()));
      for (const std::uint32_t v : curve.vertices)
        if (v >= mesh.vertex_count()) fail("border curve vertex", v);
      edges += static_cast<std::uint32_t>(curve.vertices.size()) - (curve.closed ? 0 : 1);
    }
    if (edges != border.edge_count) fail("border curves' edges", edges, border.edge_count);
  }
}

void check_skeleton(const Mesh& mesh, const Segmentation& level, const Skeleton& skeleton,
                    const SkinWeights& skin) {
  if (skeleton.bones.size() != level.cluster_count()) fail("bone count");
  if (skeleton.face_labels != level.labels) fail("skeleton labels");
  for (const Joint& joint : skeleton.joints) {
    check_finite(joint.position, "joint position");
    for (const std::uint32_t bone : joint.bones)
      if (bone >= skeleton.bones.size()) fail("joint's bone id", bone);
  }
  for (const Bone& bone : skeleton.bones) {
    check_finite(bone.axis, "bone axis");
    check_finite(bone.point, "bone point");
    check_length(bone.radius, "bone radius");
    check_length(bone.area, "bone area");
    for (const std::uint32_t joint : bone.joints)
      if (joint >= skeleton.joints.size()) fail("bone's joint id", joint);
  }
  if (skin.vertex_count() != mesh.vertex_count()) fail("skin rows");
  std::vector<char> used(mesh.vertex_count(), 0);
  for (const Triangle& t : mesh.triangles)
    for (const std::uint32_t v : t) used[v] = 1;
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    double sum = 0;
    for (const double w : skin.weights_of(v)) {
      if (!(w > 0 && w <= 1)) fail("skin weight", v, w);
      sum += w;
    }
    for (const std::uint32_t bone : skin.bones_of(v))
      if (bone >= skeleton.bones.size()) fail("skin bone id", v, bone);
    if (used[v] ? std::abs(sum - 1) > 1e-12 : !skin.bones_of(v).empty())
      fail("skin row sum", v, sum);
  }
}

std::uint32_t u32_at(const std::string& bytes, std::size_t offset) {
  std::uint32_t value = 0;
  if (offset + 4 <= bytes.size()) std::memcpy(&value, bytes.data() + offset, 4);
  return value;
}

// The GLB container and the promises of skeleton_gltf.hpp, as a glTF reader relies on them.
void check_glb(const std::string& glb, std::uint32_t vertex_count) {
  if (u32_at(glb, 0) != 0x46546C67 || u32_at(glb, 8) != glb.size()) fail("glb header");
  const std::uint32_t json_length = u32_at(glb, 12);
  const std::size_t bin_at = 20 + std::size_t{json_length};
  if (json_length % 4 != 0 || bin_at + 8 > glb.size()) fail("glb json chunk", json_length);
  const std::string bin = glb.substr(bin_at + 8);
  if (u32_at(glb, bin_at) != bin.size() || bin.size() % 4 != 0) fail("glb bin chunk");
  const nlohmann::json gltf = nlohmann::json::parse(glb.substr(20, json_length));
  if (gltf["buffers"][0]["byteLength"] != bin.size()) fail("glb buffer length");
  for (const auto& accessor : gltf["accessors"]) {
    const auto& view = gltf["bufferViews"][accessor["bufferView"].get<std::size_t>()];
    if (view["byteOffset"].get<std::size_t>() + view["byteLength"].get<std::size_t>() > bin.size())
      fail("glb view outside the buffer");
    for (const char* bound : {"min", "max"})
      if (accessor.contains(bound))
        for (const auto& x : accessor[bound])
          if (!x.is_number()) fail("glb accessor bound");
  }
  const auto& attributes = gltf["meshes"][0]["primitives"][0]["attributes"];
  std::vector<double> sums(vertex_count, 0.0);
  for (int set = 0; attributes.contains("WEIGHTS_" + std::to_string(set)); ++set) {
    const auto& accessor =
        gltf["accessors"][attributes["WEIGHTS_" + std::to_string(set)].get<std::size_t>()];
    if (accessor["count"] != vertex_count) fail("glb weight count");
    const std::size_t at =
        gltf["bufferViews"][accessor["bufferView"].get<std::size_t>()]["byteOffset"];
    for (std::size_t i = 0; i < 4 * std::size_t{vertex_count}; ++i) {
      float w = 0;
      std::memcpy(&w, bin.data() + at + 4 * i, 4);
      if (!(w >= 0 && w <= 1)) fail("glb weight", w);
      sums[i / 4] += w;
    }
  }
  for (std::uint32_t v = 0; v < vertex_count; ++v)
    if (sums[v] != 1) fail("glb weight row sum", v, sums[v]);  // exactly, as promised
}

void check_denoised(const Mesh& input, const Mesh& denoised, const SnapReport& report,
                    bool stylize) {
  if (denoised.vertex_count() != input.vertex_count() || denoised.triangles != input.triangles ||
      denoised.face_of_triangle != input.face_of_triangle)
    fail("denoising changed the connectivity");
  for (const Vec3& p : denoised.positions) check_finite(p, "denoised position");
  // The snap allows a triangle flattened to zero area; this cross product may differ from the
  // library's by round-off, hence the relative margin.
  for (const Triangle& t : input.triangles) {
    const Vec3 before = triangle_normal(input, t), after = triangle_normal(denoised, t);
    const double dot = before[0] * after[0] + before[1] * after[1] + before[2] * after[2];
    if (dot < -1e-9 * norm(before) * norm(after)) fail("denoising inverted a triangle", dot);
  }
  std::uint32_t isolated = input.vertex_count();
  std::vector<char> used(input.vertex_count(), 0);
  for (const Triangle& t : input.triangles)
    for (const std::uint32_t v : t)
      if (!used[v]) used[v] = 1, --isolated;
  if (report.snapped + report.blocked + isolated != input.vertex_count())
    fail("snap report: snapped + blocked", report.snapped, report.blocked);
  std::uint32_t changed = 0;
  for (std::uint32_t v = 0; v < input.vertex_count(); ++v)
    changed += denoised.positions[v] != input.positions[v] ? 1 : 0;
  if (report.moved != changed) fail("snap report: moved", report.moved, changed);
  if (report.interior_vertices + report.boundary_vertices + isolated != input.vertex_count())
    fail("snap report: interior + boundary", report.interior_vertices, report.boundary_vertices);
  if (!stylize && report.fallbacks > report.snapped)
    fail("snap report: fallbacks", report.fallbacks);
}

// Relations: clusters increasing and distinct, two or more (orthogonal: one or more a side); a
// parallel group and each side of an orthogonal pair share one direction up to sign, the two
// sides' directions are orthogonal to round-off, a coaxial set holds cylinders of one direction
// and spheres, every cylinder's axis and sphere's centre on its first cylinder's axis line to
// round-off, an equal-radius set cylinders and spheres of one radius, bit for bit, a coplanar set
// planes through one plane to round-off, and a tangent pair a cylinder whose axis is orthogonal to
// the plane's normal and at its radius from the plane, or two cylinders of one direction whose
// axes are the sum or the difference of their radii apart, to round-off; every deviation finite
// and not negative.
void check_relations(const std::vector<Primitive>& primitives,
                     const std::vector<ClusterRelation>& relations, const std::string& what) {
  auto check_members = [&](const std::vector<std::uint32_t>& members, std::size_t fewest,
                           bool one_direction) {
    if (members.size() < fewest || !std::is_sorted(members.begin(), members.end()) ||
        std::adjacent_find(members.begin(), members.end()) != members.end() ||
        members.back() >= primitives.size())
      fail((what + ": relation members").c_str(), double(members.size()));
    if (!one_direction) return;
    // A coaxial set's spheres have no direction.
    const auto first = std::find_if(members.begin(), members.end(), [&](std::uint32_t c) {
      return primitives[c].type != PrimitiveType::Sphere;
    });
    if (first == members.end()) return;  // a coaxial set of spheres, checked below
    const Vec3& direction = primitives[*first].axis;
    for (const std::uint32_t c : members) {
      if (primitives[c].type == PrimitiveType::Sphere) continue;
      const Vec3& axis = primitives[c].axis;
      const Vec3 a{std::abs(axis[0]), std::abs(axis[1]), std::abs(axis[2])},
          b{std::abs(direction[0]), std::abs(direction[1]), std::abs(direction[2])};
      if (a != b) fail((what + ": related directions differ").c_str(), c);
    }
  };
  for (const ClusterRelation& relation : relations) {
    const bool orthogonal = relation.kind == ClusterRelation::Kind::Orthogonal;
    const bool equal_radius = relation.kind == ClusterRelation::Kind::EqualRadius;
    const bool tangent = relation.kind == ClusterRelation::Kind::Tangent;
    const bool two_cylinders =
        tangent &&
        std::all_of(relation.clusters.begin(), relation.clusters.end(), [&](std::uint32_t c) {
          return c < primitives.size() && primitives[c].type == PrimitiveType::Cylinder;
        });
    check_members(relation.clusters, orthogonal ? 1 : 2,
                  (!equal_radius && !tangent) || two_cylinders);
    check_length(relation.deviation, (what + ": relation deviation").c_str());
    if (two_cylinders) {
      if (relation.clusters.size() != 2) fail((what + ": tangent pair's size").c_str());
      const Primitive &a = primitives[relation.clusters[0]], &b = primitives[relation.clusters[1]];
      const Vec3 apart{a.point[0] - b.point[0], a.point[1] - b.point[1], a.point[2] - b.point[2]};
      const Vec3& axis = b.axis;  // unit: one direction, checked above
      const double along = apart[0] * axis[0] + apart[1] * axis[1] + apart[2] * axis[2];
      const double distance = std::hypot(apart[0] - along * axis[0], apart[1] - along * axis[1],
                                         apart[2] - along * axis[2]);
      const double scale = std::abs(a.point[0]) + std::abs(a.point[1]) + std::abs(a.point[2]) +
                           std::abs(b.point[0]) + std::abs(b.point[1]) + std::abs(b.point[2]) +
                           a.radius + b.radius;
      if (!(std::min(std::abs(distance - (a.radius + b.radius)),
                     std::abs(distance - std::abs(a.radius - b.radius))) <= 1e-9 * scale))
        fail((what + ": tangent cylinders' axes not their radii apart").c_str(), distance);
    } else if (tangent) {
      if (relation.clusters.size() != 2) fail((what + ": tangent pair's size").c_str());
      std::uint32_t c = relation.clusters[0], p = relation.clusters[1];
      if (primitives[c].type != PrimitiveType::Cylinder) std::swap(c, p);
      if (primitives[c].type != PrimitiveType::Cylinder ||
          primitives[p].type != PrimitiveType::Plane)
        fail((what + ": tangent pair is not a cylinder and a plane, nor two cylinders").c_str());
      const Vec3 &n = primitives[p].axis, &a = primitives[c].axis;
      const double cosine = n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
      if (!(std::abs(cosine) <= 1e-12))
        fail((what + ": tangent axis not along the plane").c_str(), cosine);
      const Vec3 &q = primitives[c].point, &o = primitives[p].point;
      const double distance =
          std::abs(n[0] * (q[0] - o[0]) + n[1] * (q[1] - o[1]) + n[2] * (q[2] - o[2]));
      const double scale = std::abs(q[0]) + std::abs(q[1]) + std::abs(q[2]) + std::abs(o[0]) +
                           std::abs(o[1]) + std::abs(o[2]) + primitives[c].radius;
      if (!(std::abs(distance - primitives[c].radius) <= 1e-9 * scale))
        fail((what + ": tangent axis not at the radius from the plane").c_str(), distance);
    }
    for (const std::uint32_t c : relation.clusters) {
      const PrimitiveType type = primitives[c].type;
      if (relation.kind == ClusterRelation::Kind::Coaxial && type != PrimitiveType::Cylinder &&
          type != PrimitiveType::Sphere)
        fail((what + ": coaxial surface without an axis or a centre").c_str(), c);
      if (equal_radius && type != PrimitiveType::Cylinder && type != PrimitiveType::Sphere)
        fail((what + ": equal radius of a surface without one").c_str(), c);
    }
    if (relation.kind == ClusterRelation::Kind::Coaxial) {
      const auto cylinder = std::find_if(
          relation.clusters.begin(), relation.clusters.end(),
          [&](std::uint32_t c) { return primitives[c].type == PrimitiveType::Cylinder; });
      // Without a cylinder, three spheres or more on the line through the two farthest centres.
      Primitive line;
      if (cylinder != relation.clusters.end()) {
        line = primitives[*cylinder];
      } else {
        if (relation.clusters.size() < 3) fail((what + ": coaxial spheres, fewer than 3").c_str());
        double longest = 0;
        for (const std::uint32_t a : relation.clusters)
          for (const std::uint32_t b : relation.clusters) {
            const Vec3 &p = primitives[a].point, &q = primitives[b].point;
            const Vec3 d{q[0] - p[0], q[1] - p[1], q[2] - p[2]};
            const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (length > longest) {
              longest = length;
              line.point = p;
              line.axis = {d[0] / length, d[1] / length, d[2] / length};
            }
          }
        if (!(longest > 0)) continue;  // concentric spheres
      }
      for (const std::uint32_t c : relation.clusters) {
        const Vec3& p = primitives[c].point;
        const Vec3 d{p[0] - line.point[0], p[1] - line.point[1], p[2] - line.point[2]};
        const Vec3& a = line.axis;
        const Vec3 across{d[1] * a[2] - d[2] * a[1], d[2] * a[0] - d[0] * a[2],
                          d[0] * a[1] - d[1] * a[0]};
        const double off =
            std::sqrt(across[0] * across[0] + across[1] * across[1] + across[2] * across[2]);
        const double scale = std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2]) +
                             std::abs(line.point[0]) + std::abs(line.point[1]) +
                             std::abs(line.point[2]) + line.radius;
        if (!(off <= 1e-9 * scale)) fail((what + ": coaxial member off the axis").c_str(), off);
      }
    }
    if (relation.kind == ClusterRelation::Kind::Coplanar) {
      // Planes of one direction (checked above) through one plane, to round-off.
      const Primitive& first = primitives[relation.clusters[0]];
      for (const std::uint32_t c : relation.clusters) {
        const Vec3& p = primitives[c].point;
        if (primitives[c].type != PrimitiveType::Plane)
          fail((what + ": coplanar surface is not a plane").c_str(), c);
        const Vec3& n = first.axis;
        const double off =
            std::abs(n[0] * (p[0] - first.point[0]) + n[1] * (p[1] - first.point[1]) +
                     n[2] * (p[2] - first.point[2]));
        const double scale = std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2]) +
                             std::abs(first.point[0]) + std::abs(first.point[1]) +
                             std::abs(first.point[2]);
        if (!(off <= 1e-9 * scale)) fail((what + ": coplanar member off the plane").c_str(), off);
      }
    }
    if (relation.kind == ClusterRelation::Kind::Concentric)
      for (const std::uint32_t c : relation.clusters) {
        if (primitives[c].type != PrimitiveType::Sphere)
          fail((what + ": concentric surface is not a sphere").c_str(), c);
        if (std::bit_cast<std::array<std::uint64_t, 3>>(primitives[c].point) !=
            std::bit_cast<std::array<std::uint64_t, 3>>(primitives[relation.clusters[0]].point))
          fail((what + ": concentric centres differ").c_str(), c);
      }
    if (equal_radius)
      for (const std::uint32_t c : relation.clusters)
        if (std::bit_cast<std::uint64_t>(primitives[c].radius) !=
            std::bit_cast<std::uint64_t>(primitives[relation.clusters[0]].radius))
          fail((what + ": equal radii differ").c_str(), primitives[c].radius);
    if (!orthogonal) {
      if (!relation.orthogonal_to.empty()) fail((what + ": orthogonal_to set").c_str());
      continue;
    }
    check_members(relation.orthogonal_to, 1, true);
    if (relation.orthogonal_to[0] <= relation.clusters[0])
      fail((what + ": orthogonal sides' order").c_str());
    const Vec3 &a = primitives[relation.clusters[0]].axis,
               &b = primitives[relation.orthogonal_to[0]].axis;
    const double cosine = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    if (!(std::abs(cosine) <= 1e-12)) fail((what + ": not orthogonal").c_str(), cosine);
  }
}

// The clusters a snap used (Denoiser::snapped_level): numbered as a Segmentation, none empty,
// one report each, and borders on the denoised mesh.
void check_snapped_level(const Mesh& denoised, const SnappedLevel& level,
                         const SnapReport& report) {
  const std::size_t k = level.clusters.size();
  if (k != report.clusters) fail("snapped level: cluster count", double(k), report.clusters);
  if (level.labels.size() != denoised.face_count()) fail("snapped level: label count");
  std::vector<std::uint32_t> faces(k, 0);
  for (const std::uint32_t label : level.labels) {
    if (label >= k) fail("snapped level: label", label);
    ++faces[label];
  }
  for (std::size_t c = 0; c < k; ++c) {
    const ClusterReport& r = level.clusters[c];
    if (r.id != c || r.face_count != faces[c] || faces[c] == 0)
      fail("snapped level: cluster", double(c), r.face_count);
    if (c > 0 && level.clusters[c - 1].area < r.area) fail("snapped level: area order", double(c));
    check_length(r.area, "snapped level: area");
    check_length(r.rms, "snapped level: rms");
    check_length(r.max, "snapped level: max");
    if (r.rms > r.max * (1 + 1e-12)) fail("snapped level: rms above max", r.rms, r.max);
    check_primitive(r.primitive);
  }
  const std::vector<Primitive> primitives = cluster_primitives(level.clusters);
  check_borders(denoised, cluster_borders(denoised, level.labels, primitives));
  check_relations(primitives, level.relations, "snapped level");
}

Results run(const std::shared_ptr<const Mesh>& mesh, const Settings& settings) {
  Results results;
  results.hierarchy.emplace(build_hierarchy(mesh, settings.hierarchy));
  const Hierarchy& hierarchy = *results.hierarchy;
  fuzz::check_tree(hierarchy);
  const std::uint32_t clusters = 1 + settings.level % hierarchy.face_count();
  results.level = cut_by_count(hierarchy, clusters);

  DescribeOptions describe;
  describe.threads = 1;
  results.reports = describe_clusters(hierarchy, results.level, describe);
  check_reports(hierarchy, results.level, results.reports);

  BoundaryRefinementOptions refinement;
  refinement.describe = describe;
  results.refined = refine_boundaries(hierarchy, results.level, refinement);
  if (results.refined.segmentation.cluster_count() != results.level.cluster_count())
    fail("refinement changed the cluster count");
  fuzz::check_cut(hierarchy, results.refined.segmentation);
  check_reports(hierarchy, results.refined.segmentation, results.refined.reports);
  results.borders = cluster_borders(*mesh, results.refined.segmentation.labels,
                                    cluster_primitives(results.refined.reports));
  check_borders(*mesh, results.borders);

  // Relations made exact: members' reports refitted and valid, every other one untouched.
  std::vector<ClusterReport> regularized = results.refined.reports;
  const std::vector<ClusterRelation> relations =
      regularize_clusters(hierarchy, results.refined.segmentation, regularized);
  check_reports(hierarchy, results.refined.segmentation, regularized);
  check_relations(cluster_primitives(regularized), relations, "regularized level");
  std::vector<bool> related(regularized.size(), false);
  for (const ClusterRelation& relation : relations) {
    for (const std::uint32_t c : relation.clusters) related[c] = true;
    for (const std::uint32_t c : relation.orthogonal_to) related[c] = true;
  }
  for (std::size_t c = 0; c < regularized.size(); ++c) {
    const ClusterReport &a = regularized[c], &b = results.refined.reports[c];
    if (!related[c] &&
        (a.primitive.axis != b.primitive.axis || a.primitive.point != b.primitive.point ||
         std::bit_cast<std::uint64_t>(a.rms) != std::bit_cast<std::uint64_t>(b.rms) ||
         std::bit_cast<std::uint64_t>(a.max) != std::bit_cast<std::uint64_t>(b.max)))
      fail("regularized level: a cluster outside every relation changed", double(c));
  }

  // With tolerances as wide as a user may set them, which relate far more, the same holds.
  RelationOptions tolerant;
  tolerant.angle_tolerance_degrees = 10;
  tolerant.length_tolerance = 0.01 * bounding_box_diagonal(*mesh);
  std::vector<ClusterReport> tolerated = results.refined.reports;
  const std::vector<ClusterRelation> tolerated_relations =
      regularize_clusters(hierarchy, results.refined.segmentation, tolerated, tolerant);
  check_reports(hierarchy, results.refined.segmentation, tolerated);
  check_relations(cluster_primitives(tolerated), tolerated_relations,
                  "regularized level with tolerances");

  // The level as `primseg view --regularize` regularizes it, from its nodes' reports: the same
  // clusters, relations and reports as the cut's, bit for bit, with either options.
  for (const RelationOptions& options : {RelationOptions{}, tolerant}) {
    std::vector<std::uint32_t> nodes = results.level.nodes;
    std::sort(nodes.begin(), nodes.end());
    const LevelRegularizer regularizer(hierarchy, nodes, describe_nodes(hierarchy, nodes, describe),
                                       options, 1);
    const RegularizedLevel viewed = regularizer.level(clusters);
    std::vector<ClusterReport> cut_reports = results.reports;
    const std::vector<ClusterRelation> cut_relations =
        regularize_clusters(hierarchy, results.level, cut_reports, options);
    if (viewed.nodes != results.level.nodes) fail("level regularizer: nodes");
    if (viewed.relations.size() != cut_relations.size())
      fail("level regularizer: relations", double(viewed.relations.size()),
           double(cut_relations.size()));
    for (std::size_t r = 0; r < cut_relations.size(); ++r)
      if (viewed.relations[r].kind != cut_relations[r].kind ||
          viewed.relations[r].clusters != cut_relations[r].clusters ||
          viewed.relations[r].orthogonal_to != cut_relations[r].orthogonal_to ||
          std::bit_cast<std::uint64_t>(viewed.relations[r].deviation) !=
              std::bit_cast<std::uint64_t>(cut_relations[r].deviation))
        fail("level regularizer: relation", double(r));
    for (std::size_t c = 0; c < cut_reports.size(); ++c) {
      const ClusterReport &a = viewed.reports[c], &b = cut_reports[c];
      if (a.primitive.axis != b.primitive.axis || a.primitive.point != b.primitive.point ||
          std::bit_cast<std::uint64_t>(a.primitive.radius) !=
              std::bit_cast<std::uint64_t>(b.primitive.radius) ||
          std::bit_cast<std::uint64_t>(a.rms) != std::bit_cast<std::uint64_t>(b.rms) ||
          std::bit_cast<std::uint64_t>(a.max) != std::bit_cast<std::uint64_t>(b.max))
        fail("level regularizer: report", double(c));
    }
  }

  results.skeleton = extract_skeleton(hierarchy, results.level);
  results.skin = compute_skin_weights(*mesh, results.skeleton);
  check_skeleton(*mesh, results.level, results.skeleton, results.skin);
  check_glb(skinned_glb(*mesh, results.skeleton, results.skin), mesh->vertex_count());
  SkeletonOptions limbs;
  limbs.joints = JointRule::Limbs;
  const Skeleton limb_skeleton = extract_skeleton(hierarchy, results.level, limbs);
  check_skeleton(*mesh, results.level, limb_skeleton, compute_skin_weights(*mesh, limb_skeleton));

  Denoiser denoiser(*mesh, settings.denoise);
  const SnapReport report = settings.automatic_level ? denoiser.iterate([&](const Hierarchy& h) {
    return denoiser.automatic_level(h).segmentation;
  })
                                                     : denoiser.iterate(level_by_count(clusters));
  results.denoised = denoiser.mesh();
  check_denoised(*mesh, results.denoised, report,
                 settings.denoise.mode == SnapMode::NearestIncident);
  check_snapped_level(results.denoised, denoiser.snapped_level(), report);

  DistanceOptions distance;
  distance.samples = 200;
  distance.threads = 1;
  try {
    results.distance = mesh_distance(results.denoised, *mesh, distance);
  } catch (const InvalidInputError&) {
    // Documented: either mesh may have no triangle of positive area.
  }
  if (results.distance) {
    const MeshDistance& d = *results.distance;
    check_length(d.mean, "distance mean");
    if (!(d.mean <= d.rms * (1 + 1e-12) && d.rms <= d.hausdorff * (1 + 1e-12)))
      fail("distance: mean <= rms <= hausdorff", d.rms, d.hausdorff);
  }
  // A small picture of the level, edges drawn: every triangle rasterised, whatever its shape.
  std::vector<std::array<std::uint8_t, 3>> colors(mesh->face_count());
  for (std::uint32_t f = 0; f < colors.size(); ++f) {
    const std::uint32_t label = results.level.labels[f];
    colors[f] = {static_cast<std::uint8_t>(40 * label), static_cast<std::uint8_t>(90 + label), 200};
  }
  RenderOptions render;
  render.width = 40;
  render.height = 30;
  render.edges = true;
  results.picture = render_mesh(*mesh, colors, render);
  if (results.picture.size() != std::size_t{3} * render.width * render.height)
    fail("picture size", double(results.picture.size()));
  return results;
}

// Scaling by 2^exponent: lengths exactly so, everything else identical; but for round-off zeros
// that underflowed below the normal doubles (a denoised coordinate of -2e-322 on the grid), which
// no scaling keeps exact: those need only stay that tiny, below 2^(4|exponent|) times the
// smallest normal double (the reach of the fourth powers the fits form).
struct ScaleCheck {
  int exponent;
  bool underflowed(double x) const {
    return std::abs(x) < std::ldexp(std::numeric_limits<double>::min(), 4 * std::abs(exponent));
  }
  void scaled_by(int power, double a, double b, const char* what) const {
    if (std::ldexp(a, power) != b && !(underflowed(a) && underflowed(std::ldexp(b, -power))))
      fail(what, a, b);
  }
  void length(double a, double b, const char* what) const { scaled_by(exponent, a, b, what); }
  void area(double a, double b, const char* what) const { scaled_by(2 * exponent, a, b, what); }
  void same(double a, double b, const char* what) const {
    if (!(std::isnan(a) && std::isnan(b))) scaled_by(0, a, b, what);
  }
  void point(const Vec3& a, const Vec3& b, const char* what) const {
    for (int i = 0; i < 3; ++i) length(a[i], b[i], what);
  }
  void primitive(const Primitive& a, const Primitive& b) const {
    if (a.type != b.type) fail("scaled primitive type");
    point(a.point, b.point, "scaled primitive point");
    for (int i = 0; i < 3; ++i) same(a.axis[i], b.axis[i], "scaled primitive axis");
    length(a.radius, b.radius, "scaled primitive radius");
    length(a.minor_radius, b.minor_radius, "scaled primitive minor radius");
    same(a.half_angle, b.half_angle, "scaled primitive half angle");
  }
  void reports(const std::vector<ClusterReport>& a, const std::vector<ClusterReport>& b) const {
    for (std::size_t c = 0; c < a.size(); ++c) {
      primitive(a[c].primitive, b[c].primitive);
      primitive(a[c].algebraic, b[c].algebraic);
      area(a[c].area, b[c].area, "scaled report area");
      length(a[c].rms, b[c].rms, "scaled report rms");
      length(a[c].max, b[c].max, "scaled report max");
    }
  }
};

void check_scaled(const Results& a, const Results& b, int exponent) {
  const ScaleCheck scaled{exponent};
  const std::span<const Merge> merges = a.hierarchy->merges();
  const std::span<const Merge> scaled_merges = b.hierarchy->merges();
  for (std::size_t i = 0; i < merges.size(); ++i) {
    const Merge &m = merges[i], &s = scaled_merges[i];
    if (m.first != s.first || m.second != s.second || m.trailing != s.trailing)
      fail("scaled tree differs at merge", double(i));
    scaled.same(m.cost, s.cost, "scaled merge cost (working frame)");
    scaled.same(m.error, s.error, "scaled merge error (working frame)");
    scaled.same(m.weight, s.weight, "scaled merge weight (working frame)");
    scaled.primitive(m.primitive, s.primitive);
  }
  if (a.level.labels != b.level.labels) fail("scaled level labels");
  scaled.reports(a.reports, b.reports);
  if (a.refined.segmentation.labels != b.refined.segmentation.labels) fail("scaled refined labels");
  scaled.reports(a.refined.reports, b.refined.reports);
  if (a.borders.size() != b.borders.size()) fail("scaled border count");
  for (std::size_t i = 0; i < a.borders.size(); ++i) {
    const ClusterBorder &x = a.borders[i], &y = b.borders[i];
    if (x.first != y.first || x.second != y.second || x.edge_count != y.edge_count)
      fail("scaled border", double(i));
    scaled.length(x.length, y.length, "scaled border length");
    scaled.same(x.angle, y.angle, "scaled border angle");
    if (x.curves.size() != y.curves.size()) fail("scaled border curves", double(i));
    for (std::size_t c = 0; c < x.curves.size(); ++c)
      if (x.curves[c].vertices != y.curves[c].vertices || x.curves[c].closed != y.curves[c].closed)
        fail("scaled border curve", double(i));
  }
  if (a.skeleton.joints.size() != b.skeleton.joints.size()) fail("scaled joint count");
  for (std::size_t j = 0; j < a.skeleton.joints.size(); ++j)
    scaled.point(a.skeleton.joints[j].position, b.skeleton.joints[j].position,
                 "scaled joint position");
  for (std::size_t i = 0; i < a.skeleton.bones.size(); ++i) {
    const Bone &x = a.skeleton.bones[i], &y = b.skeleton.bones[i];
    scaled.point(x.point, y.point, "scaled bone point");
    for (int k = 0; k < 3; ++k) scaled.same(x.axis[k], y.axis[k], "scaled bone axis");
    scaled.length(x.radius, y.radius, "scaled bone radius");
    scaled.area(x.area, y.area, "scaled bone area");
  }
  if (a.skin.bones != b.skin.bones || a.skin.weights != b.skin.weights) fail("scaled skin weights");
  for (std::size_t v = 0; v < a.denoised.positions.size(); ++v)
    scaled.point(a.denoised.positions[v], b.denoised.positions[v], "scaled denoised position");
  if (a.picture != b.picture) fail("scaled picture differs");
  if (a.distance.has_value() != b.distance.has_value()) fail("scaled distance refused");
  if (a.distance) {
    scaled.length(a.distance->rms, b.distance->rms, "scaled distance rms");
    scaled.length(a.distance->hausdorff, b.distance->hausdorff, "scaled distance hausdorff");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  const Settings settings = decode_settings(data[0], data[1]);
  std::optional<Mesh> decoded = fuzz::decode_grid_mesh(data + 2, size - 2);
  if (!decoded) return 0;
  std::optional<Mesh> scaled =
      fuzz::decode_grid_mesh(data + 2, size - 2, std::ldexp(1.0, settings.exponent));
  const Results results = run(std::make_shared<const Mesh>(std::move(*decoded)), settings);
  const Results scaled_results = run(std::make_shared<const Mesh>(std::move(*scaled)), settings);
  check_scaled(results, scaled_results, settings.exponent);
  return 0;
}
