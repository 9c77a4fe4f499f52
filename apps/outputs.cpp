#include "outputs.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "../src/file_io.hpp"
#include "primseg/auto_level.hpp"
#include "primseg/borders.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/render.hpp"

namespace primseg::cli {

namespace {

// The outputs that may go to standard output: text, and the tree file for a pipe into `cut -`.
std::array<const std::optional<std::string>*, 5> standard_outputs(const OutputFiles& files) {
  return {&files.labels, &files.json, &files.linkage, &files.curve, &files.tree};
}

bool to_standard_output(const std::optional<std::string>* path) {
  return *path == kStandardOutput;
}

// Whether the file's extension names one of these mesh formats (as the mesh writers read it).
bool has_format(const std::string& path, std::initializer_list<MeshFormat> formats) {
  try {
    return std::ranges::find(formats, mesh_format_from_path(path)) != formats.end();
  } catch (const InvalidInputError&) {
    return false;  // an unknown extension, reported in the option's own terms
  }
}

}  // namespace

void validate_output_files(const OutputFiles& files) {
  const std::pair<const char*, const std::optional<std::string>*> binary[] = {
      {"--colored", &files.colored}, {"--png", &files.png}, {"--borders", &files.borders}};
  for (const auto& [option, path] : binary)
    if (*path == kStandardOutput)
      throw InvalidInputError(std::string(option) +
                              ": cannot write to standard output ('-'); only --labels, --json, "
                              "--curve, --linkage and --tree can (to write a file named '-', give "
                              "./-)");
  const auto outputs = standard_outputs(files);
  if (std::count_if(outputs.begin(), outputs.end(), to_standard_output) > 1)
    throw InvalidInputError(
        "only one of --labels, --json, --curve, --linkage and --tree can write to standard output "
        "('-')");
  // As gzip does: binary data on a terminal is garbage on the screen, and usually a mistake.
  if (files.tree == kStandardOutput && ::isatty(STDOUT_FILENO))
    throw InvalidInputError(
        "--tree -: standard output is a terminal, and a tree file is binary; redirect it "
        "(> part.tree) or pipe it (| primseg cut - --clusters 20)");
  if (files.borders && !has_format(*files.borders, {MeshFormat::Obj}))
    throw InvalidInputError("--borders: '" + *files.borders + "' must end in .obj");
  if (files.colored && !has_format(*files.colored, {MeshFormat::Ply, MeshFormat::Obj}))
    throw InvalidInputError("--colored: '" + *files.colored + "' must end in .ply or .obj");
}

std::string count_of(std::uint64_t count, std::string_view noun, std::string_view plural) {
  std::string text = std::to_string(count) + " ";
  if (count == 1 || plural.empty()) text += noun;
  if (count != 1) text += plural.empty() ? std::string_view("s") : plural;
  return text;
}

bool writes_to_standard_output(const OutputFiles& files) {
  const auto outputs = standard_outputs(files);
  return std::any_of(outputs.begin(), outputs.end(), to_standard_output);
}

void write_output(const std::string& path, std::string_view bytes) {
  if (path == kStandardOutput)
    detail::write_standard_output(bytes);
  else
    detail::write_file_atomically(path, bytes);
}

nlohmann::json primitive_params(const Primitive& primitive) {
  nlohmann::json params = nlohmann::json::object();
  for (const NamedParameter& p : named_parameters(primitive))
    params[std::string(p.name)] = p.is_vector ? vec3_json(p.value) : nlohmann::json(p.value[0]);
  return params;
}

namespace {

nlohmann::json border_json(const ClusterBorder& border) {
  nlohmann::json curves = nlohmann::json::array();
  for (const BorderCurve& curve : border.curves)
    curves.push_back({{"closed", curve.closed}, {"vertices", curve.vertices}});
  return {
      {"clusters",
       {border.first,
        border.second == kMeshBoundary ? nlohmann::json(nullptr) : nlohmann::json(border.second)}},
      {"edges", border.edge_count},
      {"length", border.length},
      {"angle", std::isnan(border.angle) ? nlohmann::json(nullptr) : nlohmann::json(border.angle)},
      {"curves", std::move(curves)}};
}

// The border curves as an OBJ file of polylines: the vertices they use, in index order, and one
// object `border_A_B` (`border_A_boundary` along the mesh's open boundary) of `l` lines per
// border, a closed curve ending at its first vertex. A comment under each object gives the
// border's edge count, length and angle, which OBJ has no field for.
std::string borders_obj(const Mesh& mesh, std::span<const ClusterBorder> borders) {
  std::vector<std::uint32_t> obj_index(mesh.vertex_count(), 0);  // 1-based, 0: not written
  for (const ClusterBorder& border : borders)
    for (const BorderCurve& curve : border.curves)
      for (const std::uint32_t v : curve.vertices) obj_index[v] = 1;
  std::string text =
      "# primseg cluster borders: one object per pair of clusters that meet, or per cluster along "
      "the open boundary\n";
  char line[128];
  std::uint32_t written = 0;
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    if (obj_index[v] == 0) continue;
    obj_index[v] = ++written;
    const Vec3& p = mesh.positions[v];
    const int n = std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
    text.append(line, static_cast<std::size_t>(n));
  }
  // (snprintf, not string concatenation: g++ 12 warns falsely on that, -Wstringop-overflow.)
  for (const ClusterBorder& border : borders) {
    const int n =
        border.second == kMeshBoundary
            ? std::snprintf(line, sizeof line, "o border_%u_boundary\n", border.first)
            : std::snprintf(line, sizeof line, "o border_%u_%u\n", border.first, border.second);
    text.append(line, static_cast<std::size_t>(n));
    const int comment =
        std::isnan(border.angle)
            ? std::snprintf(line, sizeof line, "# %u edges, length %.9g, on the open boundary\n",
                            border.edge_count, border.length)
            : std::snprintf(line, sizeof line, "# %u edges, length %.9g, angle %.9g degrees\n",
                            border.edge_count, border.length, border.angle);
    text.append(line, static_cast<std::size_t>(comment));
    for (const BorderCurve& curve : border.curves) {
      text += 'l';
      const auto append_index = [&](std::uint32_t v) {
        const int m = std::snprintf(line, sizeof line, " %u", obj_index[v]);
        text.append(line, static_cast<std::size_t>(m));
      };
      for (const std::uint32_t v : curve.vertices) append_index(v);
      if (curve.closed) append_index(curve.vertices.front());
      text += '\n';
    }
  }
  return text;
}

}  // namespace

void write_level_outputs(const Hierarchy& hierarchy, const Mesh& mesh,
                         std::span<const std::uint32_t> labels,
                         const std::vector<ClusterReport>& reports, const OutputFiles& files,
                         const nlohmann::json& summary) {
  if (files.labels) {
    std::string text;
    text.reserve(labels.size() * 4);
    for (std::uint32_t label : labels) {
      text += std::to_string(label);
      text += '\n';
    }
    write_output(*files.labels, text);
  }
  std::vector<ClusterBorder> borders;
  if (files.json || files.borders)
    borders = cluster_borders(mesh, labels, cluster_primitives(reports));
  if (files.json) {
    // A level of a cluster per face (a triangle soup at --clusters auto) held about 1.6 KB per
    // cluster as a document, 0.4 KB as text.
    nlohmann::json json = summary;
    json["clusters"] = nlohmann::json::array();
    json["borders"] = nlohmann::json::array();
    const StreamedArray clusters{"clusters", reports.size(), [&reports](std::size_t i) {
                                   const ClusterReport& r = reports[i];
                                   return nlohmann::json{
                                       {"id", r.id},
                                       {"type", std::string(to_string(r.primitive.type))},
                                       {"faces", r.face_count},
                                       {"area", r.area},
                                       {"rms", r.rms},
                                       {"max", r.max},
                                       {"params", primitive_params(r.primitive)}};
                                 }};
    const StreamedArray border_array{"borders", borders.size(),
                                     [&borders](std::size_t i) { return border_json(borders[i]); }};
    const StreamedArray arrays[] = {clusters, border_array};
    write_output(*files.json, dump_document(json, arrays));
  }
  if (files.borders) write_output(*files.borders, borders_obj(mesh, borders));
  if (files.colored) {
    const std::filesystem::path path(*files.colored);
    MeshWriteOptions options;
    options.face_groups = labels;
    write_mesh(path, mesh, options);
  }
  if (files.linkage) {
    // numpy.loadtxt gives SciPy's (F − 1, 4) linkage matrix: children, height, size.
    std::string text;
    char line[128];
    for (const auto& row : scipy_linkage(hierarchy)) {
      const int n = std::snprintf(line, sizeof line, "%.0f %.0f %.17g %.0f\n", row[0], row[1],
                                  row[2], row[3]);
      text.append(line, static_cast<std::size_t>(n));
    }
    write_output(*files.linkage, text);
  }
  if (files.curve) {
    std::string text = "k,rms\n";
    char line[64];
    for (const ErrorCurvePoint& point : error_curve(hierarchy)) {
      const int n = std::snprintf(line, sizeof line, "%u,%.17g\n", point.clusters, point.rms);
      text.append(line, static_cast<std::size_t>(n));
    }
    write_output(*files.curve, text);
  }
  if (files.png) {
    RenderOptions picture;
    picture.borders = true;
    write_png(*files.png, mesh, group_face_colors(labels), picture);
  }
}

nlohmann::json relations_json(const std::vector<ClusterRelation>& relations) {
  nlohmann::json list = nlohmann::json::array();
  for (const ClusterRelation& relation : relations) {
    nlohmann::json entry = {{"kind", to_string(relation.kind)}, {"clusters", relation.clusters}};
    if (relation.kind == ClusterRelation::Kind::Orthogonal)
      entry["orthogonal_to"] = relation.orthogonal_to;
    entry["deviation"] = relation.deviation;
    list.push_back(std::move(entry));
  }
  return list;
}

void print_summary(const std::vector<ClusterReport>& reports,
                   const std::vector<ClusterRelation>& relations, std::size_t max_rows) {
  std::printf("%s\n", count_of(reports.size(), "cluster").c_str());
  std::printf("%6s  %-8s  %8s  %12s  %12s  %12s\n", "id", "type", "faces", "area", "rms", "max");
  for (std::size_t i = 0; i < reports.size() && i < max_rows; ++i) {
    const ClusterReport& r = reports[i];
    std::printf("%6u  %-8s  %8u  %12.5g  %12.5g  %12.5g\n", r.id,
                std::string(to_string(r.primitive.type)).c_str(), r.face_count, r.area, r.rms,
                r.max);
  }
  if (reports.size() > max_rows) std::printf("   ... %zu more\n", reports.size() - max_rows);
  for (std::size_t i = 0; i < relations.size() && i < max_rows; ++i) {
    std::printf("%s:", std::string(to_string(relations[i].kind)).c_str());
    for (const std::uint32_t c : relations[i].clusters) std::printf(" %u", c);
    if (!relations[i].orthogonal_to.empty()) std::printf(" |");
    for (const std::uint32_t c : relations[i].orthogonal_to) std::printf(" %u", c);
    std::printf("\n");
  }
  if (relations.size() > max_rows)
    std::printf("   ... %zu more relations\n", relations.size() - max_rows);
}

}  // namespace primseg::cli
