// End-to-end tests of the `primseg` command-line tool: every test runs the built executable in a
// separate process on files written into a fresh temp directory, and checks what a user sees:
// exit status, output files, messages.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "primseg/hierarchy.hpp"
#include "primseg/mesh.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/primitive.hpp"
#include "primseg/relations.hpp"
#include "primseg/shape_generator.hpp"
#include "primseg/tree_io.hpp"
#include "support/regularity_shapes.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::cli_path;
using testing::run_command;

// ---------------------------------------------------------------------------------------------
// Helpers

std::string quote(const fs::path& path) {
  std::string out = "'";
  for (const char c : path.string()) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

struct CliRun {
  int status = -1;
  std::string output;  // stdout + stderr, or stderr alone for run_stderr()
};

// Runs `primseg ARGS` and captures stdout and stderr together; with `piped_from`, a shell command
// whose output is primseg's standard input.
CliRun run(const std::string& args, const std::string& piped_from = "") {
  CliRun r;
  const std::string pipe = piped_from.empty() ? "" : piped_from + " | ";
  r.status = run_command(pipe + quote(cli_path()) + " " + args, &r.output);
  return r;
}

// Runs `primseg ARGS` and captures stderr alone (stdout is discarded).
CliRun run_stderr(const std::string& args) {
  CliRun r;
  r.status = run_command("( " + quote(cli_path()) + " " + args + " >/dev/null )", &r.output);
  return r;
}

// Removes the directory when the test passed; keeps it for inspection otherwise.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) : path_(testing::temp_directory("cli-" + tag)) {}
  ~TempDir() {
    if (!::testing::Test::HasFailure()) {
      std::error_code ignored;
      fs::remove_all(path_, ignored);
    }
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  fs::path operator/(const std::string& name) const { return path_ / name; }
  std::string q(const std::string& name) const { return quote(path_ / name); }

 private:
  fs::path path_;
};

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

// Parses labels, checking their syntax strictly: one non-negative decimal integer per line, every
// line terminated by '\n', nothing else. `path` names them in failure messages.
std::vector<std::uint32_t> parse_labels(const std::string& text,
                                        const fs::path& path = "standard output") {
  std::vector<std::uint32_t> labels;
  EXPECT_FALSE(text.empty()) << path;
  if (!text.empty()) {
    EXPECT_EQ(text.back(), '\n') << path << ": last line not terminated";
  }
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(begin, end - begin);
    const bool digits = !line.empty() && std::all_of(line.begin(), line.end(),
                                                     [](char c) { return c >= '0' && c <= '9'; });
    EXPECT_TRUE(digits) << path << ": line " << labels.size() + 1 << " is '" << line << "'";
    if (!digits) return {};
    labels.push_back(static_cast<std::uint32_t>(std::stoul(line)));
    begin = end + 1;
  }
  return labels;
}

// Reads a labels file (parse_labels).
std::vector<std::uint32_t> read_labels(const fs::path& path) {
  return parse_labels(testing::file_contents(path), path);
}

json read_json(const fs::path& path) {
  const std::string text = testing::file_contents(path);
  json parsed = json::parse(text, nullptr, /*allow_exceptions=*/false);
  EXPECT_FALSE(parsed.is_discarded()) << path << " is not valid JSON:\n" << text.substr(0, 400);
  return parsed;
}

std::size_t distinct_count(const std::vector<std::uint32_t>& values) {
  return std::set<std::uint32_t>(values.begin(), values.end()).size();
}

// Checks labels are exactly 0..k-1, all used, one per face.
void expect_valid_labels(const std::vector<std::uint32_t>& labels, std::size_t faces,
                         std::size_t k) {
  ASSERT_EQ(labels.size(), faces);
  std::vector<bool> used(k, false);
  for (const std::uint32_t l : labels) {
    ASSERT_LT(l, k);
    used[l] = true;
  }
  for (std::size_t l = 0; l < k; ++l) EXPECT_TRUE(used[l]) << "label " << l << " unused";
}

double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

Vec3 json_vec3(const json& value) {
  return {value.at(0).get<double>(), value.at(1).get<double>(), value.at(2).get<double>()};
}

// True when every cluster of `labels` is connected through edges shared by its faces.
// Returns the first disconnected label in *bad.
bool clusters_connected(const Mesh& mesh, const std::vector<std::uint32_t>& labels,
                        std::uint32_t* bad) {
  std::vector<std::uint32_t> parent(mesh.face_count());
  std::iota(parent.begin(), parent.end(), 0u);
  const auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> edge_faces;
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t)
    for (int i = 0; i < 3; ++i) {
      std::uint32_t a = mesh.triangles[t][static_cast<std::size_t>(i)];
      std::uint32_t b = mesh.triangles[t][static_cast<std::size_t>((i + 1) % 3)];
      if (a > b) std::swap(a, b);
      edge_faces[{a, b}].push_back(mesh.face_of_triangle[t]);
    }
  for (const auto& [edge, faces] : edge_faces)
    for (const std::uint32_t f : faces)
      if (labels[f] == labels[faces[0]]) parent[find(f)] = find(faces[0]);
  std::map<std::uint32_t, std::uint32_t> root_of_label;
  for (std::uint32_t f = 0; f < mesh.face_count(); ++f) {
    const auto [it, inserted] = root_of_label.emplace(labels[f], find(f));
    if (!inserted && it->second != find(f)) {
      if (bad) *bad = labels[f];
      return false;
    }
  }
  return true;
}

// Per-face RGB of a binary little-endian PLY written by primseg (double xyz, uchar-length list,
// uchar red/green/blue face properties).
std::vector<std::array<std::uint8_t, 3>> ply_face_colors(const fs::path& path, std::size_t vertices,
                                                         std::size_t faces) {
  const std::string bytes = testing::file_contents(path);
  const std::size_t header_end = bytes.find("end_header\n");
  EXPECT_NE(header_end, std::string::npos);
  if (header_end == std::string::npos) return {};
  const std::string header = bytes.substr(0, header_end);
  EXPECT_NE(header.find("binary_little_endian"), std::string::npos) << header;
  EXPECT_NE(header.find("property uchar red\nproperty uchar green\nproperty uchar blue"),
            std::string::npos)
      << header;
  EXPECT_NE(header.find("property list uchar int vertex_indices"), std::string::npos) << header;
  std::size_t offset = header_end + std::string("end_header\n").size() + 24 * vertices;
  std::vector<std::array<std::uint8_t, 3>> colors;
  for (std::size_t f = 0; f < faces; ++f) {
    if (offset >= bytes.size()) break;
    const auto n = static_cast<std::uint8_t>(bytes[offset]);
    offset += 1 + 4 * std::size_t{n};
    if (offset + 3 > bytes.size()) break;
    colors.push_back({static_cast<std::uint8_t>(bytes[offset]),
                      static_cast<std::uint8_t>(bytes[offset + 1]),
                      static_cast<std::uint8_t>(bytes[offset + 2])});
    offset += 3;
  }
  EXPECT_EQ(offset, bytes.size()) << path << ": unexpected size";
  return colors;
}

// Coordinates rounded to float, so that every format (binary STL included) stores them exactly.
Mesh float_exact(Mesh mesh) {
  for (Vec3& p : mesh.positions)
    for (double& c : p) c = static_cast<double>(static_cast<float>(c));
  return mesh;
}

// Mesh of `a` and `b` side by side (b's vertices and faces after a's).
Mesh concatenate(const Mesh& a, const Mesh& b, const Vec3& offset_of_b) {
  std::vector<Vec3> positions = a.positions;
  for (Vec3 p : b.positions) {
    for (std::size_t i = 0; i < 3; ++i) p[i] += offset_of_b[i];
    positions.push_back(p);
  }
  std::vector<Triangle> triangles = a.triangles;
  for (Triangle t : b.triangles) {
    for (std::uint32_t& v : t) v += a.vertex_count();
    triangles.push_back(t);
  }
  return Mesh::from_triangles(std::move(positions), std::move(triangles));
}

const char* type_name(PrimitiveType type) {
  switch (type) {
    case PrimitiveType::Plane:
      return "plane";
    case PrimitiveType::Cylinder:
      return "cylinder";
    case PrimitiveType::Sphere:
      return "sphere";
    case PrimitiveType::Cone:
      return "cone";
    case PrimitiveType::Torus:
      return "torus";
  }
  return "?";
}

// Label of each ground-truth region when every region has a single label; empty otherwise.
std::vector<std::uint32_t> label_of_region(const GroundTruthShape& shape,
                                           const std::vector<std::uint32_t>& labels) {
  std::vector<std::set<std::uint32_t>> seen(shape.regions.size());
  for (std::size_t f = 0; f < labels.size(); ++f) seen[shape.region_of_face[f]].insert(labels[f]);
  std::vector<std::uint32_t> result;
  for (std::size_t r = 0; r < seen.size(); ++r) {
    EXPECT_EQ(seen[r].size(), 1u) << "ground-truth region " << r << " ("
                                  << type_name(shape.regions[r].type) << ") is split";
    if (seen[r].size() != 1) return {};
    result.push_back(*seen[r].begin());
  }
  return result;
}

#define EXPECT_EXIT_OK(r) EXPECT_EQ((r).status, 0) << (r).output
#define ASSERT_EXIT_OK(r) ASSERT_EQ((r).status, 0) << (r).output

// ---------------------------------------------------------------------------------------------
// 1. A full segment run on a clean CAD shape with every output.

TEST(Cli, SegmentBoxWithHoleWritesEveryOutputAndRecoversGroundTruth) {
  TempDir dir("segment");
  ShapeOptions options;
  options.random_motion = true;  // primitives in a general frame, not axis-aligned
  options.seed = 7;
  const GroundTruthShape shape = make_shape("box_with_hole", options);
  const Mesh& mesh = shape.mesh;
  const std::uint32_t f = mesh.face_count();
  ASSERT_EQ(shape.regions.size(), 7u);
  write_mesh(dir / "in.off", mesh);

  const CliRun r =
      run("segment " + dir.q("in.off") + " --clusters 7 --labels " + dir.q("l.txt") + " --json " +
          dir.q("c.json") + " --colored " + dir.q("c.ply") + " --tree " + dir.q("t.tree"));
  ASSERT_EXIT_OK(r);
  EXPECT_TRUE(fs::exists(dir / "t.tree"));

  // Labels: F lines, 0..6 all used, one label per ground-truth region, one region per label.
  const std::vector<std::uint32_t> labels = read_labels(dir / "l.txt");
  expect_valid_labels(labels, f, 7);
  const std::vector<std::uint32_t> region_label = label_of_region(shape, labels);
  ASSERT_EQ(region_label.size(), 7u);
  EXPECT_EQ(distinct_count(region_label), 7u) << "two regions share a label";
  std::vector<std::size_t> region_of_label(7);
  for (std::size_t region = 0; region < 7; ++region) region_of_label[region_label[region]] = region;

  // JSON.
  const json j = read_json(dir / "c.json");
  ASSERT_TRUE(j.is_object());
  ASSERT_TRUE(j.contains("mesh") && j["mesh"].is_object()) << j.dump(1);
  ASSERT_TRUE(j.contains("timing") && j["timing"].is_object()) << j.dump(1);
  EXPECT_EQ(j["mesh"].value("faces", 0u), f);
  EXPECT_EQ(j["mesh"].value("vertices", 0u), mesh.vertex_count());
  ASSERT_TRUE(j.contains("clusters") && j["clusters"].is_array());
  const json& clusters = j["clusters"];
  ASSERT_EQ(clusters.size(), 7u);

  const std::vector<double> areas = face_areas(mesh);
  const double mesh_area = std::accumulate(areas.begin(), areas.end(), 0.0);
  const double diagonal = bounding_box_diagonal(mesh);
  std::vector<std::uint32_t> faces_of_label(7, 0);
  std::vector<double> area_of_label(7, 0.0);
  for (std::uint32_t face = 0; face < f; ++face) {
    ++faces_of_label[labels[face]];
    area_of_label[labels[face]] += areas[face];
  }
  std::uint64_t face_sum = 0;
  double area_sum = 0;
  int planes = 0, cylinders = 0;
  for (std::size_t i = 0; i < clusters.size(); ++i) {
    const json& c = clusters[i];
    SCOPED_TRACE("cluster " + c.dump());
    for (const char* key : {"id", "type", "faces", "area", "rms", "max", "params"})
      ASSERT_TRUE(c.contains(key)) << key;
    const auto id = c["id"].get<std::uint32_t>();
    ASSERT_EQ(id, i) << "clusters are listed in label order";
    const Primitive& truth = shape.regions[region_of_label[id]];
    const std::string type = c["type"].get<std::string>();
    EXPECT_EQ(type, type_name(truth.type));
    EXPECT_EQ(c["faces"].get<std::uint32_t>(), faces_of_label[id]);
    EXPECT_NEAR(c["area"].get<double>(), area_of_label[id], 1e-9 * mesh_area);
    EXPECT_LE(c["rms"].get<double>(), 1e-9 * diagonal);
    EXPECT_LE(c["max"].get<double>(), 1e-9 * diagonal);
    EXPECT_GE(c["max"].get<double>(), 0.0);
    face_sum += c["faces"].get<std::uint64_t>();
    area_sum += c["area"].get<double>();
    const json& params = c["params"];
    if (type == "plane") {
      ++planes;
      const Vec3 normal = json_vec3(params.at("normal")), point = json_vec3(params.at("point"));
      EXPECT_NEAR(std::fabs(dot(normal, truth.axis)), 1.0, 1e-9);
      const Vec3 d{point[0] - truth.point[0], point[1] - truth.point[1], point[2] - truth.point[2]};
      EXPECT_NEAR(dot(d, truth.axis), 0.0, 1e-9 * diagonal) << "plane point off the plane";
    } else if (type == "cylinder") {
      ++cylinders;
      const double radius = params.at("radius").get<double>();
      EXPECT_NEAR(radius, truth.radius, 1e-6 * truth.radius);
      const Vec3 axis = json_vec3(params.at("axis")), point = json_vec3(params.at("point"));
      EXPECT_NEAR(std::fabs(dot(axis, truth.axis)), 1.0, 1e-9);
      // The reported point lies on the true axis.
      const Vec3 d{point[0] - truth.point[0], point[1] - truth.point[1], point[2] - truth.point[2]};
      const double along = dot(d, truth.axis);
      const double off_axis = std::sqrt(std::max(0.0, dot(d, d) - along * along));
      EXPECT_LE(off_axis, 1e-6 * diagonal);
    }
  }
  EXPECT_EQ(planes, 6);
  EXPECT_EQ(cylinders, 1);
  EXPECT_EQ(face_sum, f);
  EXPECT_NEAR(area_sum, mesh_area, 1e-9 * mesh_area);

  // Coloured PLY: a valid mesh of F faces; one colour per cluster, distinct between clusters.
  const Mesh colored = read_mesh(dir / "c.ply");
  EXPECT_EQ(colored.face_count(), f);
  EXPECT_EQ(colored.vertex_count(), mesh.vertex_count());
  const auto colors = ply_face_colors(dir / "c.ply", mesh.vertex_count(), f);
  ASSERT_EQ(colors.size(), f);
  std::map<std::uint32_t, std::array<std::uint8_t, 3>> color_of_label;
  for (std::uint32_t face = 0; face < f; ++face) {
    const auto [it, inserted] = color_of_label.emplace(labels[face], colors[face]);
    EXPECT_EQ(it->second, colors[face]) << "face " << face << " of cluster " << labels[face];
  }
  std::set<std::array<std::uint8_t, 3>> distinct_colors;
  for (const auto& [label, color] : color_of_label) distinct_colors.insert(color);
  EXPECT_EQ(distinct_colors.size(), 7u) << "clusters must get distinct colours";

  // Coloured OBJ: one `g` per cluster, and the groups hold exactly the clusters' faces.
  const CliRun obj =
      run("segment " + dir.q("in.off") + " --clusters 7 --quiet --colored " + dir.q("c.obj"));
  ASSERT_EXIT_OK(obj);
  std::istringstream lines(testing::file_contents(dir / "c.obj"));
  std::string line;
  int groups = 0;
  std::size_t faces_in_obj = 0;
  std::map<std::string, std::size_t> faces_of_group;
  std::string group;
  while (std::getline(lines, line)) {
    if (line.rfind("g ", 0) == 0 || line == "g") {
      ++groups;
      group = line;
    } else if (line.rfind("f ", 0) == 0) {
      ++faces_in_obj;
      ++faces_of_group[group];
    }
  }
  EXPECT_EQ(groups, 7);
  EXPECT_EQ(faces_in_obj, f);
  std::multiset<std::size_t> expected_sizes(faces_of_label.begin(), faces_of_label.end());
  std::multiset<std::size_t> obj_sizes;
  for (const auto& [name, count] : faces_of_group) obj_sizes.insert(count);
  EXPECT_EQ(obj_sizes, expected_sizes);
  EXPECT_EQ(read_mesh(dir / "c.obj").face_count(), f);
}

// The borders of a level: in the JSON, and as OBJ polylines through the same vertices.
TEST(Cli, SegmentWritesTheBordersInTheJsonAndAsObjPolylines) {
  TempDir dir("borders");
  ShapeOptions options;
  options.random_motion = true;
  const GroundTruthShape shape = make_shape("box_with_hole", options);
  write_mesh(dir / "in.off", shape.mesh);
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --clusters 7 --quiet --json " +
                     dir.q("c.json") + " --borders " + dir.q("b.obj")));
  const json borders = read_json(dir / "c.json").at("borders");
  // The box's 12 edges and the hole's two circles, all at right angles.
  ASSERT_EQ(borders.size(), 14u);
  std::vector<std::vector<std::uint32_t>> curves;  // every curve, closed ones ending at their start
  int closed = 0;
  for (const json& border : borders) {
    SCOPED_TRACE(border.dump().substr(0, 200));
    EXPECT_FALSE(border.at("clusters").at(1).is_null());
    EXPECT_NEAR(border.at("angle").get<double>(), 90, 1e-6);
    for (const json& curve : border.at("curves")) {
      curves.push_back(curve.at("vertices").get<std::vector<std::uint32_t>>());
      if (curve.at("closed").get<bool>()) {
        ++closed;
        curves.back().push_back(curves.back().front());
      }
    }
  }
  EXPECT_EQ(closed, 2);

  // OBJ: one object per border, one `l` per curve, through the same points.
  std::istringstream lines(testing::file_contents(dir / "b.obj"));
  std::string line;
  std::vector<Vec3> points;
  std::vector<std::string> objects;
  std::size_t curve = 0;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::string kind;
    fields >> kind;
    if (kind == "v") {
      Vec3 p;
      fields >> p[0] >> p[1] >> p[2];
      points.push_back(p);
    } else if (kind == "o") {
      objects.push_back(line);
      // Its comment: the border's edge count, length and angle.
      ASSERT_TRUE(std::getline(lines, line));
      const json& border = borders[objects.size() - 1];
      unsigned edges = 0;
      double length = 0, angle = 0;
      ASSERT_EQ(std::sscanf(line.c_str(), "# %u edges, length %lf, angle %lf degrees", &edges,
                            &length, &angle),
                3)
          << line;
      EXPECT_EQ(edges, border.at("edges").get<unsigned>());
      EXPECT_NEAR(length, border.at("length").get<double>(), 1e-8 * length);
      EXPECT_NEAR(angle, border.at("angle").get<double>(), 1e-6);
    } else if (kind == "l") {
      ASSERT_LT(curve, curves.size());
      std::vector<std::uint32_t> indices;
      for (std::uint32_t i; fields >> i;) indices.push_back(i);
      ASSERT_EQ(indices.size(), curves[curve].size());
      for (std::size_t i = 0; i < indices.size(); ++i) {
        ASSERT_GE(indices[i], 1u);
        ASSERT_LE(indices[i], points.size());
        EXPECT_EQ(points[indices[i] - 1], shape.mesh.positions[curves[curve][i]]);
      }
      ++curve;
    }
  }
  EXPECT_EQ(curve, curves.size());
  ASSERT_EQ(objects.size(), 14u);
  const json& first = borders[0].at("clusters");
  EXPECT_EQ(objects[0], "o border_" + first[0].dump() + "_" + first[1].dump());

  // `cut` writes the same borders from the tree.
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --tree " + dir.q("t.tree")));
  ASSERT_EXIT_OK(
      run("cut " + dir.q("t.tree") + " --clusters 7 --quiet --borders " + dir.q("c.obj")));
  EXPECT_EQ(testing::file_contents(dir / "c.obj"), testing::file_contents(dir / "b.obj"));

  // Polylines go to an .obj file only.
  for (const char* target : {"b.ply", "-"}) {
    const CliRun refused = run("segment " + dir.q("in.off") + " --clusters 7 --borders " +
                               (std::string(target) == "-" ? std::string("-") : dir.q(target)));
    EXPECT_NE(refused.status, 0);
    EXPECT_NE(refused.output.find("--borders"), std::string::npos) << refused.output;
  }
}

TEST(Cli, QuietPrintsNothingAndDefaultPrintsASummary) {
  TempDir dir("quiet");
  write_mesh(dir / "in.off", make_shape("box").mesh);
  const CliRun quiet = run("segment " + dir.q("in.off") + " --clusters 6 --quiet");
  EXPECT_EXIT_OK(quiet);
  EXPECT_EQ(quiet.output, "");
  const CliRun loud = run("segment " + dir.q("in.off") + " --clusters 6");
  EXPECT_EXIT_OK(loud);
  EXPECT_NE(loud.output.find("cluster"), std::string::npos) << loud.output;
}

// ---------------------------------------------------------------------------------------------
// 2. Every input format gives the same labels.

TEST(Cli, AllInputFormatsGiveIdenticalLabels) {
  TempDir dir("formats");
  ShapeOptions options;
  options.random_motion = true;
  options.seed = 3;
  options.noise = 1e-3;  // a non-trivial hierarchy, where any input difference would show
  const Mesh mesh = float_exact(make_shape("box_with_hole", options).mesh);
  const std::uint32_t f = mesh.face_count();

  struct Variant {
    std::string file;
    bool binary;
  };
  const std::vector<Variant> variants = {
      {"in.off", true}, {"in.obj", true},     {"in.ply", true},   {"ascii.ply", false},
      {"in.stl", true}, {"ascii.stl", false}, {"UPPER.OFF", true}};
  std::vector<std::uint32_t> reference;
  for (const Variant& v : variants) {
    SCOPED_TRACE(v.file);
    MeshWriteOptions write_options;
    write_options.binary = v.binary;
    if (v.file == "UPPER.OFF") {
      write_mesh(dir / "tmp.off", mesh, write_options);
      fs::rename(dir / "tmp.off", dir / v.file);
    } else {
      write_mesh(dir / v.file, mesh, write_options);
    }
    const std::string labels_file = v.file + ".labels";
    const CliRun r =
        run("segment " + dir.q(v.file) + " --clusters 9 --quiet --labels " + dir.q(labels_file));
    ASSERT_EXIT_OK(r);
    const std::vector<std::uint32_t> labels = read_labels(dir / labels_file);
    expect_valid_labels(labels, f, 9);
    if (reference.empty())
      reference = labels;
    else
      EXPECT_EQ(labels, reference) << v.file << " differs from " << variants[0].file;
  }
}

// ---------------------------------------------------------------------------------------------
// 3. `cut` on a saved tree reproduces `segment`.

TEST(Cli, CutFromTreeReproducesSegmentAtEveryLevel) {
  TempDir dir("cut");
  ShapeOptions options;
  options.noise = 2e-3;
  options.random_motion = true;
  options.seed = 11;
  const Mesh mesh = make_shape("box_with_dome", options).mesh;
  const std::uint32_t f = mesh.face_count();
  write_mesh(dir / "in.ply", mesh);
  const double diagonal = bounding_box_diagonal(mesh);

  ASSERT_EXIT_OK(run("segment " + dir.q("in.ply") + " --quiet --tree " + dir.q("t.tree")));
  // --tree - writes the same bytes to standard output, alone (no summary), for a pipe into cut.
  ASSERT_EXIT_OK(run("segment " + dir.q("in.ply") + " --tree - > " + dir.q("piped.tree")));
  EXPECT_EQ(testing::file_contents(dir / "piped.tree"), testing::file_contents(dir / "t.tree"));
  const CliRun pipeline = run("cut - --clusters 7 --labels -",
                              quote(cli_path()) + " segment " + dir.q("in.ply") + " --tree -");
  ASSERT_EXIT_OK(pipeline);
  EXPECT_EQ(pipeline.output, run("cut " + dir.q("t.tree") + " --clusters 7 --labels -").output);
  // Moving the mesh away proves `cut` does not need it.
  fs::rename(dir / "in.ply", dir / "moved.ply");

  char absolute[64];
  std::snprintf(absolute, sizeof absolute, "%.17g", 0.002 * diagonal);
  const std::vector<std::string> levels = {
      "--clusters 1",     "--clusters 2",   "--clusters 7",
      "--clusters 20",    "--tolerance 0",  std::string("--tolerance ") + absolute,
      "--tolerance 0.5%", "--tolerance 5%", "--tolerance 1e9"};
  for (const std::string& level : levels) {
    SCOPED_TRACE("level: '" + level + "'");
    const CliRun seg =
        run("segment " + dir.q("moved.ply") + " " + level + " --quiet --labels " + dir.q("s.txt") +
            " --json " + dir.q("s.json") + " --colored " + dir.q("s.ply"));
    ASSERT_EXIT_OK(seg);
    const CliRun cut =
        run("cut " + dir.q("t.tree") + " " + level + " --quiet --labels " + dir.q("c.txt") +
            " --json " + dir.q("c.json") + " --colored " + dir.q("c.ply"));
    ASSERT_EXIT_OK(cut);
    const std::vector<std::uint32_t> s = read_labels(dir / "s.txt");
    const std::vector<std::uint32_t> c = read_labels(dir / "c.txt");
    ASSERT_EQ(s.size(), f);
    EXPECT_EQ(c, s);
    // The tree piped on standard input ('-') cuts the same.
    const CliRun piped = run("cut - " + level + " --labels -", "cat " + dir.q("t.tree"));
    ASSERT_EXIT_OK(piped);
    EXPECT_EQ(piped.output, testing::file_contents(dir / "s.txt"));
    const json sj = read_json(dir / "s.json"), cj = read_json(dir / "c.json");
    ASSERT_TRUE(sj.contains("clusters") && cj.contains("clusters"));
    EXPECT_EQ(cj["clusters"], sj["clusters"]);
    EXPECT_EQ(cj["clusters"].size(), distinct_count(s));
    EXPECT_EQ(cj["mesh"].value("faces", 0u), f);
    EXPECT_EQ(testing::file_contents(dir / "c.ply"), testing::file_contents(dir / "s.ply"))
        << "coloured meshes differ";
    if (level.rfind("--clusters ", 0) == 0) {
      const auto k = std::stoul(level.substr(11));
      expect_valid_labels(c, f, k);
    }
  }
}

TEST(Cli, ToleranceLevelsAreMonotoneAndPercentIsRelativeToTheDiagonal) {
  TempDir dir("tolerance");
  ShapeOptions options;
  options.noise = 1e-3;
  const Mesh mesh = make_shape("box_with_boss", options).mesh;
  write_mesh(dir / "in.off", mesh);
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --tree " + dir.q("t.tree")));
  const double diagonal = bounding_box_diagonal(mesh);
  std::size_t previous = mesh.face_count() + 1;
  for (const double percent : {0.0, 0.01, 0.1, 1.0, 10.0, 100.0}) {
    SCOPED_TRACE(percent);
    char relative[64], absolute[64];
    std::snprintf(relative, sizeof relative, "%g%%", percent);
    const double tolerance = percent / 100 * diagonal;
    std::snprintf(absolute, sizeof absolute, "%.17g", tolerance);
    ASSERT_EXIT_OK(run("cut " + dir.q("t.tree") + " --quiet --tolerance " + relative +
                       " --labels " + dir.q("p.txt") + " --json " + dir.q("p.json")));
    ASSERT_EXIT_OK(run("cut " + dir.q("t.tree") + " --quiet --tolerance " + absolute +
                       " --labels " + dir.q("a.txt")));
    const std::vector<std::uint32_t> p = read_labels(dir / "p.txt");
    EXPECT_EQ(read_labels(dir / "a.txt"), p) << relative << " vs " << absolute;
    const std::size_t k = distinct_count(p);
    EXPECT_LE(k, previous) << "a larger tolerance gave more clusters";
    previous = k;
    // The tolerance bounds each reported cluster's RMS distance (single faces are always kept).
    const json j = read_json(dir / "p.json");
    EXPECT_EQ(j["clusters"].size(), k);
    for (const json& c : j["clusters"]) {
      if (c["faces"].get<int>() > 1) {
        EXPECT_LE(c["rms"].get<double>(), tolerance * (1 + 1e-6) + 1e-12 * diagonal) << c.dump();
      }
    }
  }
  EXPECT_EQ(previous, 1u) << "a tolerance of the whole diagonal keeps the solid in one cluster";
}

// ---------------------------------------------------------------------------------------------
// 4. Determinism.

TEST(Cli, TreeFilesAreByteIdenticalAcrossRunsAndLabelsScaleInvariant) {
  TempDir dir("determinism");
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.04;
  options.noise = 5e-4;
  options.random_motion = true;
  options.seed = 5;
  const Mesh mesh = make_shape("box_with_hole", options).mesh;
  const std::uint32_t f = mesh.face_count();
  write_mesh(dir / "in.ply", mesh);

  ASSERT_EXIT_OK(run("segment " + dir.q("in.ply") + " --quiet --tree " + dir.q("a.tree") +
                     " --clusters 12 --labels " + dir.q("a.txt") + " --json " + dir.q("a.json")));
  ASSERT_EXIT_OK(run("segment " + dir.q("in.ply") + " --quiet --tree " + dir.q("b.tree") +
                     " --clusters 12 --labels " + dir.q("b.txt")));
  const std::string a = testing::file_contents(dir / "a.tree");
  ASSERT_FALSE(a.empty());
  EXPECT_TRUE(a == testing::file_contents(dir / "b.tree")) << "two runs wrote different tree files";
  const std::vector<std::uint32_t> reference = read_labels(dir / "a.txt");
  EXPECT_EQ(read_labels(dir / "b.txt"), reference);
  expect_valid_labels(reference, f, 12);
  const json reference_json = read_json(dir / "a.json");

  for (const int exponent : {-40, 7, 40}) {
    SCOPED_TRACE("scale 2^" + std::to_string(exponent));
    const double scale = std::ldexp(1.0, exponent);
    Mesh scaled = mesh;
    for (Vec3& p : scaled.positions)
      for (double& c : p) c *= scale;
    write_mesh(dir / "scaled.ply", scaled);
    ASSERT_EXIT_OK(run("segment " + dir.q("scaled.ply") + " --quiet --clusters 12 --labels " +
                       dir.q("s.txt") + " --json " + dir.q("s.json")));
    EXPECT_EQ(read_labels(dir / "s.txt"), reference);
    const json s = read_json(dir / "s.json");
    ASSERT_EQ(s["clusters"].size(), reference_json["clusters"].size());
    for (std::size_t i = 0; i < s["clusters"].size(); ++i) {
      const json &sc = s["clusters"][i], &rc = reference_json["clusters"][i];
      EXPECT_EQ(sc["type"], rc["type"]);
      EXPECT_EQ(sc["faces"], rc["faces"]);
      EXPECT_NEAR(sc["area"].get<double>(), rc["area"].get<double>() * scale * scale,
                  1e-9 * rc["area"].get<double>() * scale * scale);
      EXPECT_NEAR(sc["rms"].get<double>(), rc["rms"].get<double>() * scale,
                  1e-6 * rc["rms"].get<double>() * scale + 1e-12 * scale);
      if (rc["params"].contains("radius")) {
        EXPECT_NEAR(sc["params"]["radius"].get<double>(),
                    rc["params"]["radius"].get<double>() * scale,
                    1e-9 * rc["params"]["radius"].get<double>() * scale);
      }
    }
    // A relative tolerance is scale-free too.
    ASSERT_EXIT_OK(run("segment " + dir.q("scaled.ply") + " --quiet --tolerance 0.3% --labels " +
                       dir.q("t.txt")));
    ASSERT_EXIT_OK(
        run("segment " + dir.q("in.ply") + " --quiet --tolerance 0.3% --labels " + dir.q("u.txt")));
    EXPECT_EQ(read_labels(dir / "t.txt"), read_labels(dir / "u.txt"));
  }
}

// ---------------------------------------------------------------------------------------------
// 5-6. A real CAD mesh.

TEST(Cli, FandiskSegmentsIntoConnectedPlanesAndCylinders) {
  const fs::path fandisk = testing::cgal_mesh("fandisk.off");
  ASSERT_TRUE(fs::exists(fandisk));
  TempDir dir("fandisk");
  const CliRun r = run("segment " + quote(fandisk) + " --quiet --clusters 25 --json " +
                       dir.q("c.json") + " --labels " + dir.q("l.txt"));
  ASSERT_EXIT_OK(r);
  const Mesh mesh = read_mesh(fandisk);
  const std::vector<std::uint32_t> labels = read_labels(dir / "l.txt");
  expect_valid_labels(labels, mesh.face_count(), 25);
  const json j = read_json(dir / "c.json");
  ASSERT_EQ(j["clusters"].size(), 25u);

  // Clusters come in decreasing area; the largest ten hold several planes and cylinders.
  int planes = 0, cylinders = 0;
  double previous_area = INFINITY;
  for (std::size_t i = 0; i < 25; ++i) {
    const json& c = j["clusters"][i];
    const double area = c["area"].get<double>();
    EXPECT_LE(area, previous_area) << "clusters not sorted by decreasing area";
    previous_area = area;
    if (i < 10) {
      planes += c["type"] == "plane";
      cylinders += c["type"] == "cylinder";
    }
  }
  EXPECT_GE(planes, 3) << j["clusters"].dump(1);
  EXPECT_GE(cylinders, 2) << j["clusters"].dump(1);

  std::uint32_t bad = 0;
  EXPECT_TRUE(clusters_connected(mesh, labels, &bad)) << "cluster " << bad << " is disconnected";
}

TEST(Cli, InfoPrintsFandiskCounts) {
  const fs::path fandisk = testing::cgal_mesh("fandisk.off");
  const CliRun r = run("info " + quote(fandisk));
  ASSERT_EXIT_OK(r);
  EXPECT_NE(r.output.find("6475"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("12946"), std::string::npos) << r.output;
  std::istringstream lines(r.output);
  std::string line;
  bool vertices = false, faces = false;
  while (std::getline(lines, line)) {
    if (line.find("vertices") != std::string::npos && line.find("6475") != std::string::npos)
      vertices = true;
    if (line.find("faces") != std::string::npos && line.find("12946") != std::string::npos)
      faces = true;
  }
  EXPECT_TRUE(vertices) << r.output;
  EXPECT_TRUE(faces) << r.output;
  EXPECT_EQ(r.output.find("out of range"), std::string::npos) << r.output;
}

TEST(Cli, InfoReportsCoordinatesTheOtherCommandsRefuse) {
  TempDir dir("info-range");
  write_file(dir / "far.off", "OFF\n3 1 0\n0 0 0\n1e40 0 0\n0 1 0\n3 0 1 2\n");
  const CliRun info = run("info " + dir.q("far.off"));
  ASSERT_EXIT_OK(info);
  EXPECT_NE(info.output.find("out of range        vertex 1 has a coordinate of magnitude 1e+40"),
            std::string::npos)
      << info.output;
  const CliRun segment = run("segment " + dir.q("far.off") + " --quiet");
  EXPECT_EQ(segment.status, 1) << segment.output;
  const CliRun as_json = run("info " + dir.q("far.off") + " --json -");
  ASSERT_EXIT_OK(as_json);
  EXPECT_EQ(json::parse(as_json.output)["out_of_range"],
            "vertex 1 has a coordinate of magnitude 1e+40, above the 1e+32 that primseg computes "
            "with")
      << as_json.output;
}

TEST(Cli, InfoJsonHasEveryCount) {
  TempDir dir("info-json");
  // A quad and a second component: three triangles on edge 4-5 (one of them a duplicate), one
  // degenerate, and an isolated vertex outside the faces' bounding box.
  write_file(dir / "defects.off",
             "OFF\n9 4 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n5 0 0\n6 0 0\n5 1 0\n7 7 7\n7 0 0\n"
             "4 0 1 2 3\n3 4 5 6\n3 6 5 4\n3 4 5 8\n");
  const CliRun r = run("info " + dir.q("defects.off") + " --json " + dir.q("info.json"));
  ASSERT_EXIT_OK(r);
  EXPECT_NE(r.output.find("vertices            9 (1 isolated)"), std::string::npos)
      << "with a file, the text is printed too: " << r.output;
  const json j = json::parse(testing::file_contents(dir / "info.json"));
  const json expected = {{"vertices", 9},
                         {"isolated_vertices", 1},
                         {"faces", 4},
                         {"polygons", 1},
                         {"triangles", 5},
                         {"components", 2},
                         {"boundary_edges", 6},
                         {"non_manifold_edges", 1},
                         {"degenerate_triangles", 1},
                         {"duplicate_triangles", 1},
                         {"inconsistent_edges", 0},
                         {"inward_components", 0},
                         {"bbox_min", {0.0, 0.0, 0.0}},
                         {"bbox_max", {7.0, 1.0, 0.0}},
                         {"bbox_diagonal", std::sqrt(50.0)},
                         {"out_of_range", nullptr}};
  EXPECT_EQ(j, expected) << j.dump(1);
}

// ---------------------------------------------------------------------------------------------
// 7. Bad input and usage: exit 1 with a message naming the problem, never a crash.

struct BadCase {
  std::string name;
  std::string args;                     // after the binary
  std::vector<std::string> substrings;  // each must appear in stderr (case-insensitive)
  bool data_error = true;               // message must start with "primseg: error:"
};

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

void expect_rejected(const BadCase& c) {
  SCOPED_TRACE(c.name + ": primseg " + c.args);
  const CliRun r = run_stderr(c.args);
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_FALSE(r.output.empty()) << "no message on stderr";
  if (c.data_error) {
    EXPECT_EQ(r.output.rfind("primseg: error:", 0), 0u) << r.output;
  }
  for (const std::string& s : c.substrings)
    EXPECT_NE(lower(r.output).find(lower(s)), std::string::npos) << "message lacks '" << s << "':\n"
                                                                 << r.output;
}

TEST(Cli, BadMeshFilesAreRejectedWithAMessage) {
  TempDir dir("bad-mesh");
  const Mesh box = make_shape("box").mesh;
  write_mesh(dir / "box.off", box);
  write_mesh(dir / "box.ply", box);
  write_file(dir / "mesh.xyz", testing::file_contents(dir / "box.off"));
  write_file(dir / "empty.off", "");
  write_file(dir / "empty.ply", "");
  const std::string ply = testing::file_contents(dir / "box.ply");
  write_file(dir / "truncated.ply", ply.substr(0, ply.size() - 7));
  write_file(dir / "nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n");
  write_file(dir / "range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  write_file(dir / "nofaces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n");
  write_file(dir / "nofaces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  write_file(dir / "garbage.stl", std::string(40, '\x01'));
  write_file(dir / "huge.off", "OFF\n3 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  write_file(dir / "far.off", "OFF\n3 1 0\n0 0 0\n1e40 0 0\n0 1 0\n3 0 1 2\n");
  write_file(dir / "speck.off", "OFF\n3 1 0\n0 0 0\n1e-40 0 0\n0 1e-40 0\n3 0 1 2\n");
  fs::create_directories(dir / "directory.off");

  const std::vector<BadCase> cases = {
      {"missing file", "segment " + dir.q("missing.off"), {"missing.off"}},
      {"unknown extension", "segment " + dir.q("mesh.xyz"), {"mesh.xyz", "extension"}},
      {"empty OFF", "segment " + dir.q("empty.off"), {"empty.off", "empty"}},
      {"empty PLY", "segment " + dir.q("empty.ply"), {"empty.ply"}},
      {"truncated binary PLY", "segment " + dir.q("truncated.ply"), {"truncated.ply"}},
      {"NaN coordinate", "segment " + dir.q("nan.off"), {"nan.off"}},
      {"index out of range", "segment " + dir.q("range.off"), {"range.off", "7"}},
      {"no faces (OFF)", "segment " + dir.q("nofaces.off"), {"no faces"}},
      {"no faces (OBJ)", "segment " + dir.q("nofaces.obj"), {"no faces"}},
      {"face count beyond the file", "segment " + dir.q("huge.off"), {"huge.off"}},
      {"garbage STL", "segment " + dir.q("garbage.stl"), {"garbage.stl"}},
      {"coordinate beyond the range", "segment " + dir.q("far.off"), {"1e+40", "1e+32"}},
      {"extent below the range",
       "denoise " + dir.q("speck.off") + " --clusters 1 -o " + dir.q("out.off"),
       {"spans 1e-40", "1e-32"}},
      {"distance beyond the range",
       "distance " + dir.q("far.off") + " " + dir.q("box.off"),
       {"1e+40"}},
      {"directory as mesh", "segment " + dir.q("directory.off"), {"directory.off"}},
      {"info on a missing file", "info " + dir.q("missing.off"), {"missing.off"}},
      {"info on a truncated file", "info " + dir.q("truncated.ply"), {"truncated.ply"}},
  };
  for (const BadCase& c : cases) expect_rejected(c);
}

TEST(Cli, TheTreeIsNotWrittenToATerminal) {
  TempDir dir("tree-terminal");
  write_mesh(dir / "box.off", make_shape("box").mesh);
  // script(1) (Debian's essential bsdutils) runs the command with a terminal as its output.
  CliRun r;
  r.status = run_command(
      "script -qec " + quote(quote(cli_path()) + " segment " + dir.q("box.off") + " --tree -") +
          " /dev/null",
      &r.output);
  EXPECT_NE(r.status, 0);
  for (const char* part :
       {"primseg: error: --tree -: standard output is a terminal", "| primseg cut - --clusters 20"})
    EXPECT_NE(r.output.find(part), std::string::npos) << r.output;
}

TEST(Cli, ClustersAutoFindsTheRegionsAndReportsCandidatesAndTheCurve) {
  TempDir dir("auto");
  ShapeOptions options;
  options.random_motion = true;
  options.seed = 7;
  const GroundTruthShape shape = make_shape("box_with_hole", options);
  write_mesh(dir / "in.off", shape.mesh);
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --clusters auto --json " +
                     dir.q("a.json") + " --curve " + dir.q("curve.csv") + " --tree " +
                     dir.q("t.tree")));
  const json j = read_json(dir / "a.json");
  EXPECT_EQ(j["level"]["clusters"], 7);
  EXPECT_EQ(j["level"]["requested_clusters"], "auto");
  EXPECT_EQ(j["clusters"].size(), 7u);
  ASSERT_TRUE(j["level"]["candidates"].is_array()) << j["level"].dump(1);
  bool listed = false;
  for (const json& c : j["level"]["candidates"]) {
    EXPECT_GE(c.at("score").get<double>(), 0.0);
    EXPECT_GE(c.at("merge_score").get<double>(), 0.0);
    EXPECT_GE(c.at("rms").get<double>(), 0.0);
    listed |= c.at("clusters") == 7;
  }
  EXPECT_TRUE(listed);

  // The curve: a header, then k = 1..F in order; one cluster per face fits exactly.
  std::istringstream lines(testing::file_contents(dir / "curve.csv"));
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "k,rms");
  std::uint32_t expected_k = 1;
  double last_rms = -1, rms_at_7 = -1, rms_at_6 = -1;
  while (std::getline(lines, line)) {
    const std::size_t comma = line.find(',');
    ASSERT_NE(comma, std::string::npos) << line;
    EXPECT_EQ(std::stoul(line.substr(0, comma)), expected_k);
    last_rms = std::stod(line.substr(comma + 1));
    if (expected_k == 6) rms_at_6 = last_rms;
    if (expected_k == 7) rms_at_7 = last_rms;
    ++expected_k;
  }
  EXPECT_EQ(expected_k - 1, shape.mesh.face_count());
  EXPECT_EQ(last_rms, 0.0);
  EXPECT_LE(rms_at_7, 1e-9 * bounding_box_diagonal(shape.mesh)) << "exact regions at K = 7";
  EXPECT_GT(rms_at_6, 1e-3 * bounding_box_diagonal(shape.mesh)) << "a jump after it";

  // cut makes the same choice from the saved tree, and both say how on the console.
  ASSERT_EXIT_OK(
      run("cut " + dir.q("t.tree") + " --quiet --clusters auto --json " + dir.q("c.json")));
  EXPECT_EQ(read_json(dir / "c.json")["clusters"], j["clusters"]);
  for (const std::string& command : {"segment " + dir.q("in.off"), "cut " + dir.q("t.tree")}) {
    const CliRun r = run(command + " --clusters auto");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("automatic level: 7 clusters, where the error curve jumps (score "),
              std::string::npos)
        << r.output;
  }
}

// The console says which rule chose the automatic level: a jump of the error curve, its knee
// when it has no jump, or one cluster per component when a single cluster fits each exactly.
TEST(Cli, ClustersAutoSaysWhichRuleChoseTheLevel) {
  TempDir dir("auto-rules");
  ShapeOptions noisy;
  noisy.noise = 0.004;
  write_mesh(dir / "box.off", make_shape("box").mesh);
  write_mesh(dir / "countersink.off", make_shape("box_with_countersink", noisy).mesh);
  write_mesh(dir / "sphere.off", make_shape("sphere").mesh);
  struct Case {
    const char* file;
    const char* line;
  };
  for (const Case& c :
       {Case{"box.off", "automatic level: 6 clusters, where the error curve jumps"},
        Case{"countersink.off",
             "automatic level: 8 clusters, the knee of the error curve (no jump)"},
        Case{"sphere.off", "automatic level: one cluster per component (no jump)"}}) {
    const CliRun r = run("segment " + dir.q(c.file) + " --clusters auto");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find(c.line), std::string::npos) << c.file << "\n" << r.output;
  }
}

TEST(Cli, RefineReportsItsPassesAndKeepsEveryFaceLabelled) {
  TempDir dir("refine");
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.noise = 0.002;
  options.seed = 2;
  options.random_motion = true;
  const GroundTruthShape shape = make_shape("slanted_box", options);
  write_mesh(dir / "in.off", shape.mesh);
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --clusters 7 --refine 3 --json " +
                     dir.q("r.json") + " --labels " + dir.q("l.txt")));
  const json j = read_json(dir / "r.json");
  ASSERT_TRUE(j["level"].contains("refinement")) << j["level"].dump(1);
  EXPECT_EQ(j["level"]["refinement"]["max_passes"], 3);
  EXPECT_LE(j["level"]["refinement"]["passes"].get<int>(), 3);
  EXPECT_TRUE(j["timing"].contains("refine_seconds"));
  expect_valid_labels(read_labels(dir / "l.txt"), shape.mesh.face_count(), 7);
}

// A box with a hole, 0.2% noise, moved at random: directions known to a fraction of a degree.
void write_noisy_box_with_hole(const fs::path& path) {
  ShapeOptions options;
  options.tessellation = Tessellation::Uniform;
  options.edge_length = 0.04;
  options.noise = 0.002;
  options.seed = 2;
  options.random_motion = true;
  write_mesh(path, make_shape("box_with_hole", options).mesh);
}

// --regularize: the JSON lists the relations made exact, the primitives are the library's
// regularize_clusters() on the same level, and the text summary lists them too.
TEST(Cli, RegularizeMakesTheRelationsExactAndListsThem) {
  TempDir dir("regularize");
  write_noisy_box_with_hole(dir / "in.off");
  const Mesh mesh = read_mesh(dir / "in.off");
  const Hierarchy hierarchy = build_hierarchy(mesh);
  const Segmentation cut = cut_by_count(hierarchy, 7);
  std::vector<ClusterReport> reports = describe_clusters(hierarchy, cut);
  const std::vector<ClusterRelation> relations = regularize_clusters(hierarchy, cut, reports);
  // Top, bottom and the hole's axis; two pairs of sides; their three right angles.
  ASSERT_EQ(relations.size(), 6u);

  const CliRun text = run("segment " + dir.q("in.off") + " --clusters 7 --regularize --tree " +
                          dir.q("t.tree") + " --json " + dir.q("s.json"));
  ASSERT_EXIT_OK(text);
  ASSERT_EXIT_OK(run("cut " + dir.q("t.tree") + " --clusters 7 --regularize --quiet --json " +
                     dir.q("c.json")));
  for (const char* file : {"s.json", "c.json"}) {
    SCOPED_TRACE(file);
    const json j = read_json(dir / file);
    ASSERT_EQ(j["relations"].size(), relations.size());
    for (std::size_t i = 0; i < relations.size(); ++i) {
      EXPECT_EQ(j["relations"][i]["kind"], std::string(to_string(relations[i].kind)));
      EXPECT_EQ(j["relations"][i]["clusters"].get<std::vector<std::uint32_t>>(),
                relations[i].clusters);
      EXPECT_EQ(j["relations"][i].value("orthogonal_to", std::vector<std::uint32_t>{}),
                relations[i].orthogonal_to);
    }
    ASSERT_EQ(j["clusters"].size(), reports.size());
    for (std::size_t c = 0; c < reports.size(); ++c) {
      const json& cluster = j["clusters"][c];
      const Primitive& p = reports[c].primitive;
      EXPECT_EQ(cluster["rms"].get<double>(), reports[c].rms) << c;
      const char* direction = p.type == PrimitiveType::Plane ? "normal" : "axis";
      EXPECT_EQ(cluster["params"][direction].get<std::vector<double>>(),
                std::vector<double>(p.axis.begin(), p.axis.end()))
          << c;
    }
  }
  for (const ClusterRelation& relation : relations) {
    std::string line = std::string(to_string(relation.kind)) + ":";
    for (const std::uint32_t c : relation.clusters) line += " " + std::to_string(c);
    if (!relation.orthogonal_to.empty()) line += " |";
    for (const std::uint32_t c : relation.orthogonal_to) line += " " + std::to_string(c);
    EXPECT_NE(text.output.find(line + "\n"), std::string::npos) << line << "\n" << text.output;
  }
  // Without it, neither the relations nor the changed fits.
  ASSERT_EXIT_OK(
      run("segment " + dir.q("in.off") + " --clusters 7 --quiet --json " + dir.q("plain.json")));
  const json plain = read_json(dir / "plain.json");
  EXPECT_FALSE(plain.contains("relations"));
  const std::vector<ClusterReport> unregularized = describe_clusters(hierarchy, cut);
  EXPECT_EQ(plain["clusters"][0]["rms"].get<double>(), unregularized[0].rms);
  EXPECT_NE(plain["clusters"][0]["rms"].get<double>(), reports[0].rms);
}

// The options of --regularize reach the library: the relations and fits are those of
// regularize_clusters() with them. A bound tighter than the noise's tilts leaves no direction
// relation; a significance too strict for the noise relates less, and tolerances wider than the
// noise then relate more. A length tolerance of T% is T/100 of the bounding-box diagonal.
TEST(Cli, RegularizeOptionsAreTheLibrarys) {
  TempDir dir("regularize-options");
  write_noisy_box_with_hole(dir / "in.off");
  const Hierarchy hierarchy = build_hierarchy(read_mesh(dir / "in.off"));
  const Segmentation cut = cut_by_count(hierarchy, 7);
  RelationOptions tight;
  tight.significance = 2.5;
  tight.max_angle_degrees = 1e-4;
  tight.max_radius_difference = 0.01;
  RelationOptions strict;
  strict.significance = 0.01;
  RelationOptions tolerant = strict;
  tolerant.angle_tolerance_degrees = 5;
  tolerant.length_tolerance = 0.05;
  RelationOptions tolerant_in_percent = tolerant;
  tolerant_in_percent.length_tolerance = 2.5 / 100 * bounding_box_diagonal(hierarchy.mesh());
  const std::vector<ClusterReport> described = describe_clusters(hierarchy, cut);
  std::vector<ClusterReport> strict_reports = described;
  const std::size_t strictly = regularize_clusters(hierarchy, cut, strict_reports, strict).size();
  for (const auto& [relation_options, flags] :
       {std::pair{tight,
                  " --relation-significance 2.5 --max-relation-angle 1e-4 "
                  "--max-radius-difference 0.01"},
        std::pair{tolerant,
                  " --relation-significance 0.01 --relation-angle-tolerance 5 "
                  "--relation-length-tolerance 0.05"},
        std::pair{tolerant_in_percent,
                  " --relation-significance 0.01 --relation-angle-tolerance 5 "
                  "--relation-length-tolerance 2.5%"}}) {
    SCOPED_TRACE(flags);
    std::vector<ClusterReport> reports = described;
    const std::vector<ClusterRelation> relations =
        regularize_clusters(hierarchy, cut, reports, relation_options);
    if (relation_options.max_angle_degrees < 1) {
      for (const ClusterRelation& relation : relations)
        EXPECT_EQ(relation.kind, ClusterRelation::Kind::EqualRadius);  // none of directions
    } else {
      EXPECT_GT(relations.size(), strictly);
    }

    ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --clusters 7 --regularize" + flags +
                       " --quiet --json " + dir.q("s.json")));
    const json j = read_json(dir / "s.json");
    ASSERT_EQ(j["relations"].size(), relations.size());
    for (std::size_t i = 0; i < relations.size(); ++i) {
      EXPECT_EQ(j["relations"][i]["clusters"].get<std::vector<std::uint32_t>>(),
                relations[i].clusters);
      EXPECT_EQ(j["relations"][i]["deviation"].get<double>(), relations[i].deviation);
    }
    ASSERT_EQ(j["clusters"].size(), reports.size());
    for (std::size_t c = 0; c < reports.size(); ++c)
      EXPECT_EQ(j["clusters"][c]["rms"].get<double>(), reports[c].rms) << c;
  }
}

// --relation-length-tolerance T% is T/100 of the mesh's bounding-box diagonal: on fandisk
// (diagonal 1.452) 0.0014% is 2.03e-5, which makes its fillet 7 tangent to its face 4 (1.7e-5
// off, docs/method.md), as that length does, bit for bit; 0.0014% of 1 (the percentage read as a
// fraction) does not.
TEST(Cli, ARelationLengthToleranceInPercentIsOfTheDiagonal) {
  TempDir dir("length-tolerance-percent");
  const fs::path fandisk = testing::cgal_mesh("fandisk.off");
  const double diagonal = bounding_box_diagonal(read_mesh(fandisk));
  const auto relations = [&](const std::string& tolerance) {
    EXPECT_EXIT_OK(run("segment " + quote(fandisk) +
                       " --clusters auto --refine 2 --regularize --relation-length-tolerance " +
                       tolerance + " --quiet --json " + dir.q("r.json")));
    const json j = read_json(dir / "r.json");
    return std::pair{j["relations"], j["clusters"]};
  };
  char length[32];
  std::snprintf(length, sizeof length, "%.17g", 0.0014 / 100 * diagonal);
  const auto in_percent = relations("0.0014%");
  EXPECT_EQ(in_percent, relations(length));
  const auto tangent_4_7 = [](const json& list) {
    return std::any_of(list.begin(), list.end(), [](const json& r) {
      return r["kind"] == "tangent" && r["clusters"] == json::array({4, 7});
    });
  };
  // fandisk's fillet 7 needs about 1.1e-5 to be tangent to its face 4: 0.0014% is 2.0e-5.
  EXPECT_TRUE(tangent_4_7(in_percent.first));
  EXPECT_FALSE(tangent_4_7(relations("0.000005").first));
}

// A bowl's two sides (exact) come out as one centre: a "concentric" relation in the JSON and the
// summary, and one center in both spheres' params, each keeping its radius.
TEST(Cli, ABowlsTwoSidesAreConcentricInTheJson) {
  TempDir dir("concentric");
  write_mesh(dir / "bowl.off", testing::spherical_bowl(0, 1));
  const CliRun r = run("segment " + dir.q("bowl.off") + " --clusters 3 --regularize --json " +
                       dir.q("bowl.json"));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("concentric: 0 1"), std::string::npos) << r.output;
  const json j = read_json(dir / "bowl.json");
  const json concentric{{"kind", "concentric"}, {"clusters", {0, 1}}};
  EXPECT_TRUE(std::any_of(j["relations"].begin(), j["relations"].end(), [&](const json& relation) {
    return relation["kind"] == concentric["kind"] && relation["clusters"] == concentric["clusters"];
  })) << j["relations"].dump();
  const json &outer = j["clusters"][0]["params"], &inner = j["clusters"][1]["params"];
  EXPECT_EQ(outer["center"], inner["center"]);
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(outer["center"][a].get<double>(), testing::kBowlCentre[a], 1e-9);
  EXPECT_NEAR(outer["radius"].get<double>(), 1.0, 1e-9);
  EXPECT_NEAR(inner["radius"].get<double>(), 0.8, 1e-9);
}

TEST(Cli, EvalScoresTheGeneratedShapes) {
  TempDir dir("eval");
  const CliRun r =
      run("eval --shapes box,capped_cylinder --variants cad --seeds 2 --json " + dir.q("e.json"));
  ASSERT_EXIT_OK(r);
  EXPECT_NE(r.output.find("mean_iou"), std::string::npos) << r.output;
  const json j = read_json(dir / "e.json");
  EXPECT_EQ(j["cases"].size(), 4u);
  const json& all = j["totals"]["all"];
  EXPECT_EQ(all["cases"], 4);
  EXPECT_DOUBLE_EQ(all["mean_iou"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(all["type_accuracy"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(all["rand_index"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(all["auto_level_exact"].get<double>(), 1.0);
  for (const json& c : j["cases"]) EXPECT_EQ(c["auto_clusters"], c["regions"]);
}

TEST(Cli, BadOptionsAreRejectedWithAMessage) {
  TempDir dir("bad-options");
  const Mesh box = make_shape("box").mesh;  // 12 triangles
  const std::uint32_t f = box.face_count();
  write_mesh(dir / "box.off", box);
  const std::string mesh = dir.q("box.off");
  const std::string too_many = std::to_string(f + 1);

  const std::vector<BadCase> cases = {
      {"--clusters 0", "segment " + mesh + " --clusters 0", {"clusters", std::to_string(f)}},
      {"--clusters F+1",
       "segment " + mesh + " --clusters " + too_many,
       {"clusters", std::to_string(f)}},
      {"--clusters -3", "segment " + mesh + " --clusters -3", {"clusters"}, false},
      {"--clusters abc", "segment " + mesh + " --clusters abc", {"clusters"}, false},
      {"--clusters automatic", "segment " + mesh + " --clusters automatic", {"clusters", "auto"}},
      {"--refine -1", "segment " + mesh + " --refine -1", {"refine"}, false},
      // Named by their flags, as the command line spells them.
      {"--relation-significance 0",
       "segment " + mesh + " --regularize --relation-significance 0",
       {"--relation-significance", "positive"},
       false},
      {"--max-relation-angle 90",
       "segment " + mesh + " --regularize --max-relation-angle 90",
       {"--max-relation-angle", "(0, 90)"},
       false},
      {"--max-relation-angle nan",
       "view " + mesh + " --regularize --max-relation-angle nan",
       {"--max-relation-angle", "nan", "(0, 90)"},
       false},
      {"--relation-angle-tolerance -1",
       "segment " + mesh + " --regularize --relation-angle-tolerance -1",
       {"--relation-angle-tolerance", "[0, 90)"},
       false},
      {"--relation-angle-tolerance above --max-relation-angle",
       "segment " + mesh + " --regularize --relation-angle-tolerance 30",
       {"--relation-angle-tolerance", "below --max-relation-angle"}},
      {"--relation-length-tolerance inf",
       "view " + mesh + " --regularize --relation-length-tolerance inf",
       {"--relation-length-tolerance", "'inf' is not a non-negative number"},
       false},
      {"--relation-length-tolerance -1%",
       "batch " + mesh + " --out x --regularize --relation-length-tolerance -1%",
       {"--relation-length-tolerance", "'-1%' is not a non-negative number"},
       false},
      {"--relation-length-tolerance 1%%",
       "segment " + mesh + " --regularize --relation-length-tolerance 1%%",
       {"--relation-length-tolerance", "(optionally followed by %)"},
       false},
      {"--max-radius-difference 1",
       "segment " + mesh + " --regularize --max-radius-difference 1",
       {"--max-radius-difference", "(0, 1)"},
       false},
      {"eval --variants banana", "eval --variants banana", {"variants", "banana"}},
      {"eval --shapes banana", "eval --shapes banana", {"banana"}},
      {"eval --seeds 0", "eval --seeds 0", {"seeds"}, false},
      {"--clusters 2^32", "segment " + mesh + " --clusters 4294967296", {"clusters"}, false},
      {"--clusters with --tolerance",
       "segment " + mesh + " --clusters 3 --tolerance 1",
       {"--clusters", "--tolerance"},
       false},
      {"--tolerance abc", "segment " + mesh + " --tolerance abc", {"tolerance", "abc"}},
      {"--tolerance -1", "segment " + mesh + " --tolerance -1", {"tolerance"}, false},
      {"--tolerance=-1", "segment " + mesh + " --tolerance=-1", {"tolerance", "-1"}},
      {"--tolerance nan", "segment " + mesh + " --tolerance nan", {"tolerance"}},
      {"--tolerance inf%", "segment " + mesh + " --tolerance inf%", {"tolerance"}},
      {"--tolerance %", "segment " + mesh + " --tolerance %", {"tolerance"}},
      {"--primitives plane,banana",
       "segment " + mesh + " --primitives plane,banana",
       {"primitives", "banana"}},
      {"--primitives empty", "segment " + mesh + " --primitives ''", {"primitives"}},
      {"--primitives duplicate", "segment " + mesh + " --primitives plane,plane", {"plane"}},
      {"--weights heavy", "segment " + mesh + " --weights heavy", {"weights", "heavy"}, false},
      {"--colored .stl",
       "segment " + mesh + " --clusters 2 --colored " + dir.q("out.stl"),
       {"colored", "out.stl"}},
      {"--colored .off",
       "segment " + mesh + " --clusters 2 --colored " + dir.q("out.off"),
       {"colored", "out.off"}},
      {"--colored no extension",
       "segment " + mesh + " --clusters 2 --colored " + dir.q("out"),
       {"colored"}},
      {"--labels into a missing directory",
       "segment " + mesh + " --clusters 2 --labels " + dir.q("no/such/dir/l.txt"),
       {"l.txt"}},
      {"--tree into a missing directory",
       "segment " + mesh + " --tree " + dir.q("no/such/dir/t.tree"),
       {"t.tree"}},
      {"--json - and --labels -",
       "segment " + mesh + " --clusters 2 --json - --labels -",
       {"only one", "standard output"}},
      {"--png -", "segment " + mesh + " --clusters 2 --png -", {"--png", "standard output"}},
      {"--colored -",
       "segment " + mesh + " --clusters 2 --colored -",
       {"--colored", "standard output"}},
      {"--tree - and --json -",
       "segment " + mesh + " --tree - --json -",
       {"only one", "--tree", "standard output"}},
      {"unknown option", "segment " + mesh + " --frobnicate", {"frobnicate"}, false},
      {"missing mesh argument", "segment --clusters 3", {"MESH"}, false},
      {"unknown subcommand", "frobnicate " + mesh, {"frobnicate"}, false},
      {"no subcommand", "", {"subcommand"}, false},
      {"cut without a tree", "cut --clusters 2", {"TREE"}, false},
      {"--tree given to cut", "cut " + dir.q("t.tree") + " --tree x", {"tree"}, false},
  };
  for (const BadCase& c : cases) expect_rejected(c);

  // A rejected --colored must not be discovered only after other outputs were written.
  // (Reported, not asserted: see the NOTE test below.)
}

TEST(Cli, BadTreeFilesAreRejectedWithAMessage) {
  TempDir dir("bad-tree");
  const Mesh mesh = make_shape("capped_cylinder").mesh;
  write_mesh(dir / "in.off", mesh);
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --tree " + dir.q("t.tree")));
  const std::string tree = testing::file_contents(dir / "t.tree");
  ASSERT_GT(tree.size(), 100u);
  std::string flipped = tree;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 0x10);
  write_file(dir / "flipped.tree", flipped);
  std::string flipped_checksum = tree;
  flipped_checksum.back() = static_cast<char>(flipped_checksum.back() ^ 0x01);
  write_file(dir / "checksum.tree", flipped_checksum);
  write_file(dir / "truncated.tree", tree.substr(0, tree.size() / 2));
  write_file(dir / "header-only.tree", tree.substr(0, 10));
  write_file(dir / "empty.tree", "");
  write_file(dir / "extended.tree", tree + std::string(16, '\0'));
  std::string magic_only = tree.substr(0, 8);
  write_file(dir / "magic.tree", magic_only);
  // The header up to the vertex count, then a count of 2^50 vertices (little-endian).
  const std::size_t vertex_count_at = 8 + 4 + 3 + static_cast<unsigned char>(tree[14]) + 48;
  std::string huge_count = tree.substr(0, vertex_count_at) + std::string(6, '\0');
  huge_count += std::string{'\x04', '\0'} + std::string(64, '\0');
  write_file(dir / "huge-count.tree", huge_count);

  const std::vector<BadCase> cases = {
      {"flipped byte", "cut " + dir.q("flipped.tree") + " --clusters 2", {"flipped.tree"}},
      {"flipped checksum", "cut " + dir.q("checksum.tree") + " --clusters 2", {"checksum.tree"}},
      {"truncated", "cut " + dir.q("truncated.tree") + " --clusters 2", {"truncated.tree"}},
      {"header only", "cut " + dir.q("header-only.tree") + " --clusters 2", {"header-only"}},
      {"magic only", "cut " + dir.q("magic.tree") + " --clusters 2", {"magic.tree"}},
      {"empty", "cut " + dir.q("empty.tree") + " --clusters 2", {"empty.tree"}},
      {"trailing bytes", "cut " + dir.q("extended.tree") + " --clusters 2", {"extended.tree"}},
      {"mesh passed as a tree", "cut " + dir.q("in.off") + " --clusters 2", {"in.off"}},
      {"missing tree", "cut " + dir.q("missing.tree") + " --clusters 2", {"missing.tree"}},
      {"truncated on standard input",
       "cut - --clusters 2 < " + dir.q("truncated.tree"),
       {"standard input", "truncated"}},
      {"nothing on standard input",
       "cut - --clusters 2 < " + dir.q("empty.tree"),
       {"standard input", "empty"}},
      {"a mesh on standard input", "cut - --clusters 2 < " + dir.q("in.off"), {"standard input"}},
      {"a tree on standard input beyond --max-memory",
       "cut - --clusters 2 --max-memory 1K < " + dir.q("t.tree"),
       {"standard input", "--max-memory"}},
      {"endless zeros on standard input", "cut - --clusters 2 < /dev/zero", {"bad magic"}},
      {"a tree whose counts declare more than can be read, on standard input",
       "cut - --clusters 2 < " + dir.q("huge-count.tree"),
       {"standard input", "declare", "the most this read accepts"}},
      {"tree passed as a mesh", "segment " + dir.q("t.tree"), {"t.tree"}},
      {"cut --clusters 0", "cut " + dir.q("t.tree") + " --clusters 0", {"clusters"}},
      {"cut --clusters F+1",
       "cut " + dir.q("t.tree") + " --clusters " + std::to_string(mesh.face_count() + 1),
       {"clusters", std::to_string(mesh.face_count())}},
      {"cut --tolerance abc", "cut " + dir.q("t.tree") + " --tolerance abc", {"tolerance"}},
      {"cut --clusters with --tolerance",
       "cut " + dir.q("t.tree") + " --clusters 2 --tolerance 1%",
       {"--clusters", "--tolerance"},
       false},
      {"cut --colored .stl",
       "cut " + dir.q("t.tree") + " --clusters 2 --colored " + dir.q("o.stl"),
       {"o.stl"}},
  };
  for (const BadCase& c : cases) expect_rejected(c);

  // A pipe that never ends stops as soon as it cannot be a tree: after the counts of a header
  // followed by zeros, or a whole tree followed by more bytes.
  for (const std::string& producer : {"(head -c 15 " + dir.q("t.tree") + "; cat /dev/zero)",
                                      "(cat " + dir.q("t.tree") + "; cat /dev/zero)"}) {
    const CliRun r = run("cut - --clusters 2", producer);
    EXPECT_EQ(r.status, 1) << producer << ": " << r.output;
    EXPECT_NE(r.output.find("unexpected data after the tree's checksum"), std::string::npos)
        << r.output;
  }

  // Every single-byte corruption at a few dozen positions across the file is caught (the
  // checksum covers everything), never crashes.
  for (std::size_t k = 0; k < 24; ++k) {
    const std::size_t at = k * (tree.size() - 1) / 23;
    std::string bad = tree;
    bad[at] = static_cast<char>(bad[at] ^ 0x40);
    write_file(dir / "sweep.tree", bad);
    const CliRun r = run_stderr("cut " + dir.q("sweep.tree") + " --clusters 2");
    EXPECT_EQ(r.status, 1) << "byte " << at << ": " << r.output;
  }
  // Truncation at every length in a sweep: rejected, never a crash.
  for (std::size_t k = 0; k < 16; ++k) {
    const std::size_t length = k * (tree.size() - 1) / 15;
    write_file(dir / "cut.tree", tree.substr(0, length));
    const CliRun r = run_stderr("cut " + dir.q("cut.tree") + " --clusters 2");
    EXPECT_EQ(r.status, 1) << "length " << length << ": " << r.output;
  }
}

// The synopsis makes the level mandatory for cut: `cut TREE (--clusters K | --tolerance T)`.
TEST(Cli, CutRequiresALevel) {
  TempDir dir("cut-level");
  write_mesh(dir / "in.off", make_shape("box").mesh);
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --tree " + dir.q("t.tree")));
  expect_rejected({"cut without a level", "cut " + dir.q("t.tree"), {"--clusters"}, false});
}

// Segment's level is optional: the default tolerance gives a valid segmentation, as does cut's
// explicit equivalent on the same tree.
TEST(Cli, SegmentWithoutALevelUsesTheDefaultTolerance) {
  TempDir dir("default-level");
  const GroundTruthShape shape = make_shape("box_with_hole");
  write_mesh(dir / "in.off", shape.mesh);
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --labels " + dir.q("d.txt") +
                     " --tree " + dir.q("t.tree")));
  const std::vector<std::uint32_t> d = read_labels(dir / "d.txt");
  ASSERT_EQ(d.size(), shape.mesh.face_count());
  EXPECT_EQ(label_of_region(shape, d).size(), shape.regions.size());
  EXPECT_EQ(distinct_count(d), shape.regions.size());
}

TEST(Cli, HelpAndVersionExitZero) {
  const CliRun help = run("--help");
  EXPECT_EQ(help.status, 0) << help.output;
  EXPECT_NE(help.output.find("segment"), std::string::npos) << help.output;
  EXPECT_NE(help.output.find("cut"), std::string::npos) << help.output;
  EXPECT_NE(help.output.find("info"), std::string::npos) << help.output;
  for (const char* command : {"segment --help", "cut --help", "info --help"}) {
    const CliRun r = run(command);
    EXPECT_EQ(r.status, 0) << command << "\n" << r.output;
    EXPECT_NE(r.output.find("--"), std::string::npos) << command << "\n" << r.output;
  }
  const CliRun segment_help = run("segment --help");
  for (const char* option : {"--clusters", "--tolerance", "--primitives", "--weights", "--labels",
                             "--json", "--colored", "--tree", "--exact-costs", "--quiet"})
    EXPECT_NE(segment_help.output.find(option), std::string::npos) << option;
  const CliRun version = run("--version");
  EXPECT_EQ(version.status, 0) << version.output;
}

// ---------------------------------------------------------------------------------------------
// 8. Several connected components.

TEST(Cli, DisjointComponentsAreNeverMerged) {
  TempDir dir("components");
  const GroundTruthShape box = make_shape("box");
  ASSERT_EQ(box.regions.size(), 6u);
  const Mesh two = concatenate(box.mesh, box.mesh, {10, 0, 0});
  const std::uint32_t f = two.face_count();
  const std::uint32_t half = box.mesh.face_count();
  write_mesh(dir / "two.off", two);

  ASSERT_EXIT_OK(run("segment " + dir.q("two.off") + " --quiet --clusters 1 --labels " +
                     dir.q("one.txt") + " --json " + dir.q("one.json") + " --tree " +
                     dir.q("t.tree")));
  const std::vector<std::uint32_t> one = read_labels(dir / "one.txt");
  expect_valid_labels(one, f, 2);
  for (std::uint32_t face = 0; face < f; ++face)
    EXPECT_EQ(one[face], one[face < half ? 0 : half]) << "face " << face;
  EXPECT_NE(one[0], one[half]);
  const json j = read_json(dir / "one.json");
  EXPECT_EQ(j["clusters"].size(), 2u);
  EXPECT_EQ(j["mesh"].value("components", 0u), 2u) << j["mesh"].dump();

  ASSERT_EXIT_OK(run("segment " + dir.q("two.off") + " --quiet --clusters 12 --labels " +
                     dir.q("twelve.txt")));
  const std::vector<std::uint32_t> twelve = read_labels(dir / "twelve.txt");
  expect_valid_labels(twelve, f, 12);
  // Each box face (ground-truth region of either copy) is exactly one cluster.
  std::map<std::pair<int, std::uint32_t>, std::set<std::uint32_t>> labels_of_region;
  for (std::uint32_t face = 0; face < f; ++face) {
    const int copy = face < half ? 0 : 1;
    labels_of_region[{copy, box.region_of_face[face % half]}].insert(twelve[face]);
  }
  ASSERT_EQ(labels_of_region.size(), 12u);
  std::set<std::uint32_t> all;
  for (const auto& [region, labels] : labels_of_region) {
    EXPECT_EQ(labels.size(), 1u);
    all.insert(labels.begin(), labels.end());
  }
  EXPECT_EQ(all.size(), 12u);

  // Same through cut, and a huge tolerance still leaves one cluster per component.
  ASSERT_EXIT_OK(
      run("cut " + dir.q("t.tree") + " --quiet --clusters 1 --labels " + dir.q("c1.txt")));
  EXPECT_EQ(read_labels(dir / "c1.txt"), one);
  ASSERT_EXIT_OK(
      run("cut " + dir.q("t.tree") + " --quiet --tolerance 1e300 --labels " + dir.q("tol.txt")));
  EXPECT_EQ(distinct_count(read_labels(dir / "tol.txt")), 2u);
}

// ---------------------------------------------------------------------------------------------
// 9. Degenerate input.

TEST(Cli, DegenerateMeshesAreSegmented) {
  TempDir dir("degenerate");
  const Mesh box = make_shape("box").mesh;
  std::vector<Vec3> positions = box.positions;
  std::vector<Triangle> triangles = box.triangles;
  const auto add = [&](const Vec3& p) {
    positions.push_back(p);
    return static_cast<std::uint32_t>(positions.size() - 1);
  };
  triangles.push_back(box.triangles[0]);  // duplicate face
  triangles.push_back(box.triangles[3]);  // another duplicate
  // Zero-area face: three collinear new vertices hanging off a box vertex.
  const Vec3 p0 = box.positions[0];
  const std::uint32_t c1 = add({p0[0] + 1, p0[1] + 1, p0[2] + 1});
  const std::uint32_t c2 = add({p0[0] + 2, p0[1] + 2, p0[2] + 2});
  triangles.push_back({0, c1, c2});
  // Non-manifold edge: a fin on the first triangle's edge (a third face on that edge).
  const Triangle t0 = box.triangles[0];
  const std::uint32_t fin = add({p0[0] - 3, p0[1] + 0.5, p0[2] - 2});
  triangles.push_back({t0[0], t0[1], fin});
  // Isolated vertices.
  add({100, 100, 100});
  add({-100, 5, 5});
  const Mesh mesh = Mesh::from_triangles(std::move(positions), std::move(triangles));
  const std::uint32_t f = mesh.face_count();
  write_mesh(dir / "bad.off", mesh);
  write_mesh(dir / "bad.ply", mesh);

  for (const std::string file : {"bad.off", "bad.ply"})
    for (const std::string level : {"--clusters 1", "--clusters 6", "--clusters 16", ""}) {
      SCOPED_TRACE(file + " " + level);
      const CliRun r = run("segment " + dir.q(file) + " --quiet " + level + " --labels " +
                           dir.q("l.txt") + " --json " + dir.q("c.json") + " --colored " +
                           dir.q("c.ply") + " --tree " + dir.q("t.tree"));
      ASSERT_EXIT_OK(r);
      const std::vector<std::uint32_t> labels = read_labels(dir / "l.txt");
      ASSERT_EQ(labels.size(), f);
      const std::size_t k = distinct_count(labels);
      expect_valid_labels(labels, f, k);
      const json j = read_json(dir / "c.json");
      EXPECT_EQ(j["clusters"].size(), k);
      for (const json& c : j["clusters"]) {
        EXPECT_TRUE(std::isfinite(c["area"].get<double>())) << c.dump();
        EXPECT_TRUE(std::isfinite(c["rms"].get<double>())) << c.dump();
      }
      EXPECT_EQ(read_mesh(dir / "c.ply").face_count(), f);
      // cut needs the level spelled out: segment's default is --tolerance 0.1%.
      const std::string cut_level = level.empty() ? "--tolerance 0.1%" : level;
      const CliRun cut =
          run("cut " + dir.q("t.tree") + " --quiet " + cut_level + " --labels " + dir.q("cl.txt"));
      ASSERT_EXIT_OK(cut);
      EXPECT_EQ(read_labels(dir / "cl.txt"), labels);
    }
  const CliRun info = run("info " + dir.q("bad.off"));
  EXPECT_EXIT_OK(info);
  EXPECT_NE(info.output.find(std::to_string(f)), std::string::npos) << info.output;
}

TEST(Cli, TinyAndFullyDegenerateMeshesAreSegmented) {
  TempDir dir("tiny");
  struct Case {
    std::string name, off;
    std::uint32_t faces;
  };
  const std::vector<Case> cases = {
      {"one_triangle", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 1},
      {"one_quad", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n", 1},
      {"zero_area_only", "OFF\n3 2 0\n0 0 0\n1 1 1\n2 2 2\n3 0 1 2\n3 2 1 0\n", 2},
      {"all_points_equal", "OFF\n3 2 0\n1 1 1\n1 1 1\n1 1 1\n3 0 1 2\n3 0 2 1\n", 2},
      {"repeated_index", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 0 1\n3 0 1 2\n", 2},
      {"two_far_triangles",
       "OFF\n6 2 0\n0 0 0\n1 0 0\n0 1 0\n1e30 0 0\n1e30 1 0\n1e30 0 1\n3 0 1 2\n3 3 4 5\n", 2},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    write_file(dir / (c.name + ".off"), c.off);
    const CliRun r =
        run("segment " + dir.q(c.name + ".off") + " --quiet --labels " + dir.q(c.name + ".txt") +
            " --json " + dir.q(c.name + ".json") + " --tree " + dir.q(c.name + ".tree"));
    EXPECT_TRUE(r.status == 0 || r.status == 1) << "crash, status " << r.status << "\n" << r.output;
    EXPECT_EQ(r.status, 0) << r.output;
    if (r.status != 0) continue;
    const std::vector<std::uint32_t> labels = read_labels(dir / (c.name + ".txt"));
    EXPECT_EQ(labels.size(), c.faces);
    const json j = read_json(dir / (c.name + ".json"));
    EXPECT_EQ(j["clusters"].size(), distinct_count(labels));
    const CliRun all = run("cut " + dir.q(c.name + ".tree") + " --quiet --clusters " +
                           std::to_string(c.faces) + " --labels " + dir.q("all.txt"));
    EXPECT_EXIT_OK(all);
    EXPECT_EQ(distinct_count(read_labels(dir / "all.txt")), c.faces);
  }
}

// ---------------------------------------------------------------------------------------------
// 10. Options that change the hierarchy.

TEST(Cli, ExactCostsAgreeWithDefaultOnCleanShapes) {
  TempDir dir("exact");
  for (const std::string name : {"box_with_hole", "capped_cylinder", "box_with_dome"}) {
    SCOPED_TRACE(name);
    const GroundTruthShape shape = make_shape(name);
    const std::string k = std::to_string(shape.regions.size());
    write_mesh(dir / "in.off", shape.mesh);
    ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --clusters " + k + " --labels " +
                       dir.q("d.txt")));
    ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --exact-costs --clusters " + k +
                       " --labels " + dir.q("e.txt") + " --tree " + dir.q("e.tree")));
    const std::vector<std::uint32_t> d = read_labels(dir / "d.txt");
    EXPECT_EQ(read_labels(dir / "e.txt"), d);
    EXPECT_EQ(label_of_region(shape, d).size(), shape.regions.size());
    ASSERT_EXIT_OK(
        run("cut " + dir.q("e.tree") + " --quiet --clusters " + k + " --labels " + dir.q("c.txt")));
    EXPECT_EQ(read_labels(dir / "c.txt"), d);
  }
}

TEST(Cli, PrimitivesAndWeightsOptionsAreHonoured) {
  TempDir dir("primitives");
  const GroundTruthShape shape = make_shape("box_with_hole");
  write_mesh(dir / "in.off", shape.mesh);
  // Planes only: every cluster is a plane.
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") +
                     " --quiet --primitives plane --clusters 12 --json " + dir.q("p.json") +
                     " --tree " + dir.q("p.tree")));
  const json p = read_json(dir / "p.json");
  ASSERT_EQ(p["clusters"].size(), 12u);
  for (const json& c : p["clusters"]) EXPECT_EQ(c["type"], "plane") << c.dump();
  // The tree remembers the options: cut gives planes too.
  ASSERT_EXIT_OK(
      run("cut " + dir.q("p.tree") + " --quiet --clusters 12 --json " + dir.q("pc.json")));
  EXPECT_EQ(read_json(dir / "pc.json")["clusters"], p["clusters"]);

  // A sphere-only run still reports spheres, in a different order of the list.
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") +
                     " --quiet --primitives sphere,plane --clusters 7 --json " + dir.q("s.json")));
  // Keep the document alive: a range-for over a member of a temporary would dangle.
  const json sphere_run = read_json(dir / "s.json");
  for (const json& c : sphere_run["clusters"])
    EXPECT_TRUE(c["type"] == "plane" || c["type"] == "sphere") << c.dump();

  // Uniform weights: a valid segmentation, still perfect at the true K on this clean shape.
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") +
                     " --quiet --weights uniform --clusters 7 --labels " + dir.q("u.txt")));
  const std::vector<std::uint32_t> u = read_labels(dir / "u.txt");
  expect_valid_labels(u, shape.mesh.face_count(), 7);
  EXPECT_EQ(label_of_region(shape, u).size(), 7u);
}

TEST(Cli, PolygonFacesKeepOneLabelPerInputFace) {
  // An OBJ with quads: labels are per input polygon, not per triangle.
  TempDir dir("polygons");
  const std::string cube =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
      "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  write_file(dir / "cube.obj", cube);
  ASSERT_EXIT_OK(run("segment " + dir.q("cube.obj") + " --quiet --clusters 6 --labels " +
                     dir.q("l.txt") + " --json " + dir.q("c.json") + " --colored " +
                     dir.q("c.obj")));
  expect_valid_labels(read_labels(dir / "l.txt"), 6, 6);
  const json j = read_json(dir / "c.json");
  EXPECT_EQ(j["mesh"].value("faces", 0u), 6u);
  for (const json& c : j["clusters"]) {
    EXPECT_EQ(c["faces"], 1) << c.dump();
    EXPECT_NEAR(c["area"].get<double>(), 1.0, 1e-12) << c.dump();
  }
  const Mesh colored = read_mesh(dir / "c.obj");
  EXPECT_EQ(colored.face_count(), 6u);
  EXPECT_EQ(colored.triangle_count(), 12u);
}

// File names are bytes on Linux: spaces, quotes, UTF-8 and even invalid UTF-8 must work, also in
// the JSON's "mesh" entry.
TEST(Cli, UnusualFileNamesWork) {
  TempDir dir("names");
  const Mesh box = make_shape("box").mesh;
  for (const std::string name :
       {"with space's.off", "caf\xc3\xa9 \xe2\x88\x85.off", "invalid-utf8-\xff\xfe.off"}) {
    SCOPED_TRACE(name);
    write_mesh(dir / name, box);
    const CliRun r =
        run("segment " + dir.q(name) + " --quiet --clusters 6 --labels " + dir.q(name + ".txt") +
            " --json " + dir.q(name + ".json") + " --tree " + dir.q(name + ".tree"));
    EXPECT_TRUE(r.status == 0 || r.status == 1) << "status " << r.status << "\n" << r.output;
    EXPECT_EQ(r.status, 0) << r.output;
    if (r.status != 0) continue;
    expect_valid_labels(read_labels(dir / (name + ".txt")), box.face_count(), 6);
    EXPECT_EQ(read_json(dir / (name + ".json"))["clusters"].size(), 6u);
    const CliRun cut = run("cut " + dir.q(name + ".tree") + " --quiet --clusters 6 --json " +
                           dir.q(name + ".cut.json"));
    EXPECT_EQ(cut.status, 0) << cut.output;
  }
}

// The page carries the file name in a <script> element: a name that would open a comment and a
// script there ("<!--<script>" puts the HTML parser in a state where "</script>" no longer ends
// the element) is escaped, so the data stays inside its element.
TEST(Cli, ViewEscapesTheFileNameInsideItsScript) {
  TempDir dir("view-name");
  const std::string name = "<!--<script>box.off";
  write_mesh(dir / name, make_shape("box").mesh);
  const CliRun r = run("view " + dir.q(name) + " --quiet -o " + dir.q("page.html"));
  if (r.output.find("without the web viewer") != std::string::npos)
    GTEST_SKIP() << "this primseg has no web viewer";
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string page = testing::file_contents(dir / "page.html");
  EXPECT_NE(page.find("\\u003c!--\\u003cscript>box.off"), std::string::npos);
  EXPECT_EQ(page.find("<!--<script>box.off"), std::string::npos);
}

TEST(Cli, OutputsOverwriteExistingFiles) {
  TempDir dir("overwrite");
  write_mesh(dir / "in.off", make_shape("box").mesh);
  write_file(dir / "l.txt", std::string(100000, 'x'));
  ASSERT_EXIT_OK(
      run("segment " + dir.q("in.off") + " --quiet --clusters 6 --labels " + dir.q("l.txt")));
  expect_valid_labels(read_labels(dir / "l.txt"), 12, 6);
}

// Drops the timing entries, the only part of a level's JSON that changes from run to run.
json without_timing(json j) {
  j.erase("timing");
  return j;
}

TEST(Cli, DashWritesATextOutputToStandardOutputAlone) {
  TempDir dir("stdout");
  write_mesh(dir / "in.off", make_shape("box_with_hole").mesh);
  const std::string level = " --clusters 7";
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + level + " --quiet --tree " + dir.q("t.tree") +
                     " --labels " + dir.q("l.txt") + " --json " + dir.q("j.json") + " --curve " +
                     dir.q("c.csv") + " --linkage " + dir.q("k.txt")));
  // run() captures stdout and stderr together: a summary or a message would spoil the output.
  const std::pair<const char*, const char*> outputs[] = {
      {"--labels", "l.txt"}, {"--curve", "c.csv"}, {"--linkage", "k.txt"}};
  for (const auto& [option, file] : outputs) {
    SCOPED_TRACE(option);
    const CliRun r = run("segment " + dir.q("in.off") + level + " " + option + " -");
    ASSERT_EXIT_OK(r);
    EXPECT_EQ(r.output, testing::file_contents(dir / file));
  }
  for (const std::string& command : {"segment " + dir.q("in.off"), "cut " + dir.q("t.tree")}) {
    SCOPED_TRACE(command);
    const CliRun r = run(command + level + " --json -");
    ASSERT_EXIT_OK(r);
    const json parsed = json::parse(r.output, nullptr, /*allow_exceptions=*/false);
    ASSERT_FALSE(parsed.is_discarded()) << r.output.substr(0, 400);
    EXPECT_EQ(parsed["clusters"], read_json(dir / "j.json")["clusters"]);
  }
  const CliRun denoised =
      run("denoise " + dir.q("in.off") + level + " -o " + dir.q("d.off") + " --json -");
  ASSERT_EXIT_OK(denoised);
  EXPECT_EQ(json::parse(denoised.output)["clusters"].size(), 7u);
  const CliRun labelled =
      run("segment " + dir.q("in.off") + level + " --json " + dir.q("j2.json") + " --labels -");
  ASSERT_EXIT_OK(labelled);
  EXPECT_EQ(labelled.output, testing::file_contents(dir / "l.txt"));
  EXPECT_EQ(without_timing(read_json(dir / "j2.json")), without_timing(read_json(dir / "j.json")));
  EXPECT_FALSE(fs::exists("-")) << "'-' named a file in the working directory";

  // A write that fails is an error, not a silently truncated output.
  CliRun full;
  full.status = run_command(
      "( " + quote(cli_path()) + " segment " + dir.q("in.off") + level + " --json - >/dev/full )",
      &full.output);
  EXPECT_EQ(full.status, 1) << full.output;
  EXPECT_NE(full.output.find("primseg: error: cannot write to standard output"), std::string::npos)
      << full.output;
}

TEST(Cli, DashReadsTheMeshFromStandardInputInAnyFormat) {
  TempDir dir("stdin");
  const Mesh mesh = make_shape("box_with_hole").mesh;
  const std::string level = " --clusters 7 --labels -";
  for (const char* name : {"in.off", "in.obj", "in.ply", "in.stl"}) {
    SCOPED_TRACE(name);
    write_mesh(dir / name, mesh);
    const CliRun by_path = run("segment " + dir.q(name) + level);
    ASSERT_EXIT_OK(by_path);
    const CliRun piped = run("segment -" + level + " < " + dir.q(name));
    ASSERT_EXIT_OK(piped);
    EXPECT_EQ(piped.output, by_path.output);
    const CliRun through_cat =
        run("segment -" + level + " --primitives plane", "cat " + dir.q(name));
    ASSERT_EXIT_OK(through_cat);  // a pipe, whose size is unknown until its end
    expect_valid_labels(parse_labels(through_cat.output), mesh.face_count(), 7);
  }
  const CliRun info = run("info - < " + dir.q("in.off"));
  ASSERT_EXIT_OK(info);
  EXPECT_EQ(info.output.rfind("standard input\n", 0), 0u) << info.output;
  const CliRun summary = run("segment - --clusters 7 < " + dir.q("in.ply"));
  ASSERT_EXIT_OK(summary);
  EXPECT_EQ(summary.output.rfind(
                "standard input: " + std::to_string(mesh.face_count()) + " faces, 1 component,", 0),
            0u)
      << summary.output;
  const CliRun distance =
      run("distance - " + dir.q("in.obj") + " -q --json - < " + dir.q("in.off"));
  ASSERT_EXIT_OK(distance);
  EXPECT_LT(json::parse(distance.output)["symmetric"]["max"].get<double>(), 1e-9);  // one shape
  ASSERT_EXIT_OK(run("denoise - --clusters 7 -o " + dir.q("d.off") + " < " + dir.q("in.off")));
  EXPECT_EQ(read_mesh(dir / "d.off").face_count(), mesh.face_count());

  // Standard input that holds no mesh: exit 1 with a message naming it.
  write_file(dir / "empty", "");
  write_file(dir / "page.html", "<html>not a mesh</html>\n");
  const std::pair<std::string, std::string> bad[] = {
      {"segment - --clusters 2 < " + dir.q("empty"), "standard input: empty"},
      {"segment - --clusters 2 < " + dir.q("page.html"), "standard input: not a mesh file"},
      {"info - < " + dir.q("page.html"), "standard input: not a mesh file"},
      {"distance - - < " + dir.q("in.off"), "distance: only one of A and B"}};
  for (const auto& [args, message] : bad) {
    SCOPED_TRACE(args);
    const CliRun r = run(args);
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("primseg: error: " + message), std::string::npos) << r.output;
  }
}

// Blocks of 64 KiB that `dd` wrote into a pipe before its reader closed it: its "N+0 records out"
// (dd ignores SIGPIPE here so that it reports the write that failed).
int records_written(const fs::path& dd_report) {
  const std::string text = testing::file_contents(dd_report);
  const std::size_t at = text.find("+0 records out");
  EXPECT_NE(at, std::string::npos) << text;
  if (at == std::string::npos) return -1;
  const std::size_t line = text.rfind('\n', at);
  return std::stoi(text.substr(line == std::string::npos ? 0 : line + 1));
}

TEST(Cli, AStreamOnStandardInputIsReadOnlyWhileItCanBeAMeshWithinMaxMemory) {
  TempDir dir("stream");
  // 256 MiB offered in blocks of 64 KiB; primseg must stop after a few of them.
  const std::string offered = " bs=65536 count=4096 2> " + dir.q("dd.txt") + ")";
  // Zeros (a device or a corrupt upload) are no format from their first 64 KiB on.
  CliRun zeros = run("info -", "(trap '' PIPE; dd if=/dev/zero" + offered);
  EXPECT_EQ(zeros.status, 1) << zeros.output;
  EXPECT_NE(zeros.output.find("primseg: error: standard input: not a mesh file"), std::string::npos)
      << zeros.output;
  EXPECT_LT(records_written(dir / "dd.txt"), 16);
  // Text that reads as OBJ is read up to --max-memory, not to its end.
  CliRun vertices = run("segment - --max-memory 1M",
                        "(trap '' PIPE; yes 'v 1 2 3' 2>/dev/null | dd iflag=fullblock" + offered);
  EXPECT_EQ(vertices.status, 1) << vertices.output;
  EXPECT_NE(vertices.output.find("primseg: error: standard input: more than --max-memory 1048576 "
                                 "bytes"),
            std::string::npos)
      << vertices.output;
  EXPECT_LT(records_written(dir / "dd.txt"), 32);
  // A mesh within the limit (the process and its 208 faces: about 8.6 MB) is read whole, by
  // pieces of any size.
  write_mesh(dir / "in.ply", make_shape("box_with_hole").mesh);
  ASSERT_EXIT_OK(run("segment - --max-memory 16M --clusters 7 --quiet",
                     "dd bs=1000 2>/dev/null < " + dir.q("in.ply")));
}

TEST(Cli, SummariesCountInWords) {
  TempDir dir("words");
  write_file(dir / "one.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const CliRun segment = run("segment " + dir.q("one.off") + " --clusters 1");
  ASSERT_EXIT_OK(segment);
  EXPECT_NE(segment.output.find("one.off: 1 face, 1 component, hierarchy in"), std::string::npos)
      << segment.output;
  EXPECT_NE(segment.output.find("\n1 cluster\n"), std::string::npos) << segment.output;
  const CliRun denoise = run("denoise " + dir.q("one.off") + " --clusters 1 -o " + dir.q("d.off"));
  ASSERT_EXIT_OK(denoise);
  EXPECT_NE(denoise.output.find("round 1: 1 cluster, 3 vertices snapped"), std::string::npos)
      << denoise.output;
  fs::create_directory(dir / "in");
  write_file(dir / "in" / "one.off", testing::file_contents(dir / "one.off"));
  const CliRun batch = run("batch " + dir.q("in") + " --out " + dir.q("out") + " --clusters 1");
  ASSERT_EXIT_OK(batch);
  EXPECT_EQ(batch.output.rfind("1 file: 1 ok,", 0), 0u) << batch.output;
}

TEST(Cli, ThreadCountDoesNotChangeTheTree) {
  TempDir dir("threads");
  write_mesh(dir / "in.off", read_mesh(testing::cgal_mesh("fandisk.off")));
  for (const char* threads : {"1", "2", "3"})
    ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --threads " + threads + " --tree " +
                       dir.q(std::string("t") + threads + ".tree")));
  EXPECT_EQ(testing::file_contents(dir / "t1.tree"), testing::file_contents(dir / "t2.tree"));
  EXPECT_EQ(testing::file_contents(dir / "t1.tree"), testing::file_contents(dir / "t3.tree"));
}

// `segment --quiet` with an approximate option (`option`, the library's `options`) writes the
// library's tree, the same for any thread count and not the exact order's.
void expect_the_librarys_approximate_tree(const std::string& option,
                                          const HierarchyOptions& options) {
  TempDir dir("approximate");
  const Mesh mesh = read_mesh(testing::cgal_mesh("fandisk.off"));
  write_mesh(dir / "in.off", mesh);
  for (const char* threads : {"1", "2"})
    ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet " + option + " --threads " +
                       threads + " --tree " + dir.q(std::string("t") + threads)));
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --tree " + dir.q("exact")));
  const std::string approximate = testing::file_contents(dir / "t1");
  EXPECT_EQ(testing::file_contents(dir / "t2"), approximate) << option;
  EXPECT_NE(testing::file_contents(dir / "exact"), approximate) << option;
  EXPECT_EQ(serialize_tree(build_hierarchy(read_mesh(dir / "in.off"), options)), approximate)
      << option;
}

// --merge-batch-tolerance builds the library's batched tree, and a bad value is refused before the
// mesh is read.
TEST(Cli, MergeBatchToleranceBuildsTheBatchedTree) {
  HierarchyOptions options;
  options.merge_batch_tolerance = 0.1;
  expect_the_librarys_approximate_tree("--merge-batch-tolerance 0.1", options);
  const CliRun refused = run("segment missing.off --merge-batch-tolerance -1");
  EXPECT_NE(refused.status, 0);
  EXPECT_NE(refused.output.find("--merge-batch-tolerance"), std::string::npos) << refused.output;
}

// --regions builds the library's tree in regions; a bad count, or regions with --exact-costs, is
// refused.
TEST(Cli, RegionsBuildTheTreeInRegions) {
  HierarchyOptions options;
  options.regions = 2;
  expect_the_librarys_approximate_tree("--regions 2", options);
  for (const char* bad : {"--regions 0", "--regions 257", "--regions two"}) {
    const CliRun refused = run(std::string("segment missing.off ") + bad);
    EXPECT_NE(refused.status, 0) << bad;
    EXPECT_NE(refused.output.find("--regions"), std::string::npos) << refused.output;
  }
  TempDir dir("regions");
  write_mesh(dir / "in.off", make_shape("box_with_hole").mesh);
  const CliRun exact_costs =
      run("segment " + dir.q("in.off") + " --quiet --regions 2 --exact-costs");
  EXPECT_EQ(exact_costs.status, 1);
  EXPECT_NE(exact_costs.output.find("exact_costs"), std::string::npos) << exact_costs.output;
}

TEST(Cli, LinkageIsAValidScipyLinkageMatrixOfTheWholeTree) {
  TempDir dir("linkage");
  const GroundTruthShape shape = make_shape("box_with_hole");
  write_mesh(dir / "in.off", shape.mesh);
  ASSERT_EXIT_OK(run("segment " + dir.q("in.off") + " --quiet --clusters 7 --tree " +
                     dir.q("t.tree") + " --linkage " + dir.q("z.txt")));
  ASSERT_EXIT_OK(
      run("cut " + dir.q("t.tree") + " --quiet --clusters 3 --linkage " + dir.q("z2.txt")));
  EXPECT_EQ(testing::file_contents(dir / "z.txt"), testing::file_contents(dir / "z2.txt"));
  // SciPy's rules (scipy.cluster.hierarchy.is_valid_linkage): n − 1 rows; row i joins two
  // existing clusters (< n + i), each used once; the size is the sum of the children's sizes.
  const std::uint32_t n = shape.mesh.face_count();
  std::ifstream in(dir / "z.txt");
  std::vector<double> size(2 * n - 1, 1.0);
  std::vector<int> used(2 * n - 1, 0);
  double a, b, cost, count;
  std::uint32_t rows = 0;
  while (in >> a >> b >> cost >> count) {
    ASSERT_LT(rows, n - 1);
    const auto i = static_cast<std::uint32_t>(a), j = static_cast<std::uint32_t>(b);
    EXPECT_EQ(double(i), a);
    EXPECT_LT(i, n + rows);
    EXPECT_LT(j, n + rows);
    EXPECT_EQ(used[i]++, 0);
    EXPECT_EQ(used[j]++, 0);
    EXPECT_TRUE(std::isfinite(cost) && cost >= 0) << cost;
    EXPECT_EQ(count, size[i] + size[j]);
    size[n + rows] = count;
    ++rows;
  }
  EXPECT_EQ(rows, n - 1);
  EXPECT_EQ(size[2 * n - 2], double(n));
}

}  // namespace
}  // namespace primseg
