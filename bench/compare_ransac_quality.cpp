// The quality half of primseg_compare_cgal (`--quality`): primseg against CGAL's Efficient RANSAC
// (Schnabel et al. 2007; planes, spheres, cylinders, cones and tori) on the generated shapes with
// ground truth, scored as `primseg eval` scores primseg (evaluation.hpp): mean IoU after
// Hungarian matching, area-weighted type accuracy, area-weighted Rand index, and time.
//
// RANSAC works on points with normals, so each shape is sampled: kSamplesPerShape points,
// uniform by area, each with its face's normal. A face takes the shape most of its samples were
// assigned to; a face without an assigned sample takes the detected shape nearest to its
// centroid (what a user does to turn RANSAC's point labels into a segmentation). Parameters are
// relative to the bounding-box diagonal and the sample spacing (see ransac_parameters), chosen
// once for the whole set, as a user would; primseg runs with its defaults at the true number of
// regions. The random generators of both the sampling and CGAL are seeded: reruns agree.

#include "compare_ransac_quality.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Random.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>
#include <CGAL/property_map.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/evaluation.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/shape_generator.hpp"

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
// A sample: point, unit normal, and the face it lies on. Efficient RANSAC reorders its input, so
// the face travels with the point.
using Sample = std::tuple<Kernel::Point_3, Kernel::Vector_3, std::uint32_t>;
using Samples = std::vector<Sample>;
using Traits =
    CGAL::Shape_detection::Efficient_RANSAC_traits<Kernel, Samples,
                                                   CGAL::Nth_of_tuple_property_map<0, Sample>,
                                                   CGAL::Nth_of_tuple_property_map<1, Sample>>;
using EfficientRansac = CGAL::Shape_detection::Efficient_RANSAC<Traits>;

constexpr std::size_t kSamplesPerShape = 20000;

struct Variant {
  const char* name;
  primseg::Tessellation tessellation;
  double noise;
};
// The variants of `primseg eval`.
constexpr Variant kVariants[] = {{"cad", primseg::Tessellation::Cad, 0.0},
                                 {"uniform", primseg::Tessellation::Uniform, 0.0},
                                 {"noisy", primseg::Tessellation::Uniform, 0.002}};

std::array<double, 3> corner(const primseg::Mesh& mesh, std::uint32_t vertex) {
  return mesh.positions[vertex];
}

// Area-uniform samples of the mesh, each with its face's unit normal.
Samples sample_surface(const primseg::Mesh& mesh, std::uint64_t seed) {
  std::vector<double> cumulative;
  double total = 0;
  for (const primseg::Triangle& t : mesh.triangles) {
    const auto a = corner(mesh, t[0]), b = corner(mesh, t[1]), c = corner(mesh, t[2]);
    const Kernel::Vector_3 n =
        CGAL::cross_product(Kernel::Vector_3(b[0] - a[0], b[1] - a[1], b[2] - a[2]),
                            Kernel::Vector_3(c[0] - a[0], c[1] - a[1], c[2] - a[2]));
    total += std::sqrt(n.squared_length()) / 2;
    cumulative.push_back(total);
  }
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  Samples samples;
  samples.reserve(kSamplesPerShape);
  for (std::size_t i = 0; i < kSamplesPerShape; ++i) {
    const double at = uniform(random) * total;
    const auto triangle = static_cast<std::uint32_t>(std::min<std::size_t>(
        std::upper_bound(cumulative.begin(), cumulative.end(), at) - cumulative.begin(),
        cumulative.size() - 1));
    const primseg::Triangle& t = mesh.triangles[triangle];
    double u = uniform(random), v = uniform(random);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const auto a = corner(mesh, t[0]), b = corner(mesh, t[1]), c = corner(mesh, t[2]);
    Kernel::Vector_3 n =
        CGAL::cross_product(Kernel::Vector_3(b[0] - a[0], b[1] - a[1], b[2] - a[2]),
                            Kernel::Vector_3(c[0] - a[0], c[1] - a[1], c[2] - a[2]));
    const double length = std::sqrt(n.squared_length());
    if (length > 0) n = n / length;
    const Kernel::Point_3 p(a[0] + u * (b[0] - a[0]) + v * (c[0] - a[0]),
                            a[1] + u * (b[1] - a[1]) + v * (c[1] - a[1]),
                            a[2] + u * (b[2] - a[2]) + v * (c[2] - a[2]));
    samples.emplace_back(p, n, mesh.face_of_triangle[triangle]);
  }
  return samples;
}

EfficientRansac::Parameters ransac_parameters(const primseg::Mesh& mesh) {
  const double diagonal = primseg::bounding_box_diagonal(mesh);
  double area = 0;
  for (const double a : primseg::face_areas(mesh)) area += a;
  const double spacing = std::sqrt(area / kSamplesPerShape);
  EfficientRansac::Parameters parameters;
  parameters.probability = 0.01;
  parameters.min_points = kSamplesPerShape / 200;  // regions of 0.5% of the area or more
  // 3 sigma of the noisy variant's noise (0.2% of the diagonal), and well above round-off.
  parameters.epsilon = 0.006 * diagonal;
  parameters.cluster_epsilon = 3 * spacing;
  parameters.normal_threshold = 0.9;  // about 25 degrees
  return parameters;
}

primseg::PrimitiveType type_of(const EfficientRansac::Shape& shape) {
  using namespace CGAL::Shape_detection;
  if (dynamic_cast<const Sphere<Traits>*>(&shape)) return primseg::PrimitiveType::Sphere;
  if (dynamic_cast<const Cylinder<Traits>*>(&shape)) return primseg::PrimitiveType::Cylinder;
  if (dynamic_cast<const Cone<Traits>*>(&shape)) return primseg::PrimitiveType::Cone;
  if (dynamic_cast<const Torus<Traits>*>(&shape)) return primseg::PrimitiveType::Torus;
  return primseg::PrimitiveType::Plane;
}

struct Labelled {
  std::vector<std::uint32_t> labels;          // per face
  std::vector<primseg::PrimitiveType> types;  // per cluster
};

// RANSAC's shapes as a face segmentation (see the file comment).
Labelled run_ransac(const primseg::Mesh& mesh, std::uint64_t seed) {
  Samples samples = sample_surface(mesh, seed);
  CGAL::get_default_random() = CGAL::Random(static_cast<unsigned>(seed));
  EfficientRansac ransac;
  ransac.set_input(samples);
  ransac.add_shape_factory<CGAL::Shape_detection::Plane<Traits>>();
  ransac.add_shape_factory<CGAL::Shape_detection::Sphere<Traits>>();
  ransac.add_shape_factory<CGAL::Shape_detection::Cylinder<Traits>>();
  ransac.add_shape_factory<CGAL::Shape_detection::Cone<Traits>>();
  ransac.add_shape_factory<CGAL::Shape_detection::Torus<Traits>>();
  ransac.detect(ransac_parameters(mesh));

  Labelled out;
  const auto range = ransac.shapes();
  // CGAL 5.5 hands out boost::shared_ptr.
  const std::vector<std::remove_cvref_t<decltype(*range.begin())>> shapes(range.begin(),
                                                                          range.end());
  const std::uint32_t faces = mesh.face_count();
  out.labels.assign(faces, 0);
  if (shapes.empty()) {  // nothing detected: the whole mesh is one unlabelled cluster
    out.types = {primseg::PrimitiveType::Plane};
    return out;
  }
  std::fprintf(stderr, "  RANSAC: %zu shapes, %zu of %zu samples unassigned\n", shapes.size(),
               ransac.number_of_unassigned_points(), samples.size());
  std::vector<std::map<std::uint32_t, std::uint32_t>> votes(faces);
  for (std::uint32_t s = 0; s < shapes.size(); ++s) {
    out.types.push_back(type_of(*shapes[s]));
    for (const std::size_t i : shapes[s]->indices_of_assigned_points())
      ++votes[std::get<2>(samples[i])][s];
  }
  // Centroid of each face (of its first triangle: faces are triangles here).
  std::vector<Kernel::Point_3> centroid(faces);
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const primseg::Triangle& tri = mesh.triangles[t];
    const auto a = corner(mesh, tri[0]), b = corner(mesh, tri[1]), c = corner(mesh, tri[2]);
    centroid[mesh.face_of_triangle[t]] = Kernel::Point_3(
        (a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3);
  }
  for (std::uint32_t f = 0; f < faces; ++f) {
    if (!votes[f].empty()) {
      out.labels[f] =
          std::max_element(votes[f].begin(), votes[f].end(), [](const auto& x, const auto& y) {
            return x.second < y.second;
          })->first;
      continue;
    }
    double nearest = INFINITY;
    for (std::uint32_t s = 0; s < shapes.size(); ++s) {
      const double d = shapes[s]->squared_distance(centroid[f]);
      if (d < nearest) nearest = d, out.labels[f] = s;
    }
  }
  return out;
}

Labelled run_primseg(const primseg::GroundTruthShape& shape) {
  const primseg::Hierarchy hierarchy = primseg::build_hierarchy(shape.mesh);
  const primseg::Segmentation segmentation =
      primseg::cut_by_count(hierarchy, static_cast<std::uint32_t>(shape.regions.size()));
  Labelled out;
  out.labels = segmentation.labels;
  for (const primseg::ClusterReport& r : primseg::describe_clusters(hierarchy, segmentation))
    out.types.push_back(r.primitive.type);
  return out;
}

struct Totals {
  double iou = 0, types = 0, rand = 0, seconds = 0;
  int cases = 0;
  std::array<double, primseg::kPrimitiveTypeCount> area{}, correct{};

  void add(const primseg::SegmentationScore& s, double time) {
    iou += s.mean_iou, types += s.type_accuracy, rand += s.rand_index, seconds += time;
    ++cases;
    for (int t = 0; t < primseg::kPrimitiveTypeCount; ++t)
      area[t] += s.area_by_type[t], correct[t] += s.correct_area_by_type[t];
  }
  void print(const char* variant, const char* method) const {
    std::printf("| %s | %s | %d | %.4f | %.4f | %.4f | %.3f |", variant, method, cases, iou / cases,
                types / cases, rand / cases, seconds);
    for (int t = 0; t < primseg::kPrimitiveTypeCount; ++t) {
      if (area[t] > 0)
        std::printf(" %.2f |", correct[t] / area[t]);
      else
        std::printf(" – |");
    }
    std::printf("\n");
  }
};

}  // namespace

int run_ransac_quality_comparison(int seeds) {
  using Clock = std::chrono::steady_clock;
  std::printf(
      "| variant | method | cases | mean IoU | type accuracy | Rand index | seconds "
      "| plane | cylinder | sphere | cone | torus |\n"
      "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  Totals all_primseg, all_ransac;
  for (const Variant& variant : kVariants) {
    Totals primseg_totals, ransac_totals;
    for (const std::string& name : primseg::shape_names())
      for (int seed = 1; seed <= seeds; ++seed) {
        primseg::ShapeOptions options;
        options.tessellation = variant.tessellation;
        options.noise = variant.noise;
        options.random_motion = true;
        options.seed = static_cast<std::uint64_t>(seed);
        const primseg::GroundTruthShape shape = primseg::make_shape(name, options);
        const std::vector<double> areas = primseg::face_areas(shape.mesh);
        std::vector<primseg::PrimitiveType> truth_types;
        for (const primseg::Primitive& p : shape.regions) truth_types.push_back(p.type);
        std::fprintf(stderr, "%s %s seed %d\n", variant.name, name.c_str(), seed);
        for (int method = 0; method < 2; ++method) {
          const auto start = Clock::now();
          const Labelled result =
              method == 0 ? run_primseg(shape) : run_ransac(shape.mesh, 1000 + options.seed);
          const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
          const primseg::SegmentationScore score = primseg::score_segmentation(
              result.labels, shape.region_of_face, areas, result.types, truth_types);
          (method == 0 ? primseg_totals : ransac_totals).add(score, seconds);
          (method == 0 ? all_primseg : all_ransac).add(score, seconds);
        }
      }
    primseg_totals.print(variant.name, "primseg (true K)");
    ransac_totals.print(variant.name, "CGAL Efficient RANSAC");
  }
  all_primseg.print("all", "primseg (true K)");
  all_ransac.print("all", "CGAL Efficient RANSAC");
  return 0;
}
