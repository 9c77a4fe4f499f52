// The paper's section 7 experiment on a real CAD mesh: fandisk with Gaussian noise of 0.3% of its
// bounding-box diagonal along the vertex normals, denoised at several levels and measured against
// the clean mesh (Metro-style). Prints the table the README quotes. With PRIMSEG_FIGURES_DIR set,
// also writes the README's before/after pictures there, and the automatic level's clusters on
// the denoised mesh with their borders.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "denoise_test_support.hpp"
#include "primseg/auto_level.hpp"
#include "primseg/cut.hpp"
#include "primseg/denoise.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_distance.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/render.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

// Out of line: GCC 12 inlines the default HierarchyOptions into the long test body and then
// warns (wrongly) that the primitive list may be used uninitialized.
[[gnu::noinline]] DenoiseOptions bilateral_options() {
  DenoiseOptions options;
  options.bilateral_smoothing = BilateralSmoothingOptions{};
  return options;
}

TEST(DenoiseFandisk, NoiseOfAThirdOfAPercentDropsWithASmoothedSegmentation) {
  const Mesh clean = read_mesh(testing::cgal_mesh("fandisk.off"));
  const double sigma = 0.003 * bounding_box_diagonal(clean);
  const Mesh noisy = testing::with_normal_noise(clean, sigma, 2006);
  DistanceOptions measure;
  measure.samples = 200000;
  const MeshDistance before = mesh_distance(noisy, clean, measure);
  std::printf("fandisk: diagonal %.5g, sigma %.4g\n", before.diagonal, sigma);
  std::printf("%8s %12s %12s %8s %12s %8s\n", "K", "rms", "hausdorff", "rms /", "smoothing",
              "haus /");
  std::printf("%8s %12.4g %12.4g\n", "noisy", before.rms, before.hausdorff);
  double best_ratio = 0;
  std::uint32_t best_k = 0;
  // Smoothing of the segmented copy: none, 5 Taubin steps (-5 in the table), bilateral (1).
  for (const int smoothing : {0, -5, 1})
    for (const std::uint32_t k : {20u, 30u, 40u, 60u}) {
      DenoiseOptions options;
      if (smoothing < 0) options.smoothing_steps = -smoothing;
      if (smoothing == 1) options.bilateral_smoothing = BilateralSmoothingOptions{};
      Denoiser denoiser(noisy, options);
      const SnapReport report = denoiser.iterate(level_by_count(k));
      const MeshDistance after = mesh_distance(denoiser.mesh(), clean, measure);
      std::printf("%8u %12.4g %12.4g %8.2f %12s %8.2f   (%u fallbacks, %u blocked)\n", k, after.rms,
                  after.hausdorff, before.rms / after.rms,
                  smoothing == 0  ? "none"
                  : smoothing < 0 ? "taubin 5"
                                  : "bilateral",
                  before.hausdorff / after.hausdorff, report.fallbacks, report.blocked);
      EXPECT_EQ(testing::inverted_triangles(noisy, denoiser.mesh()), 0u);
      if (smoothing != 0 && k >= 30) {
        EXPECT_LT(after.rms * 2, before.rms);
      }
      if (smoothing == 1 && k >= 40) {
        EXPECT_LT(after.rms * 3, before.rms);
      }
      if (before.rms / after.rms > best_ratio) {
        best_ratio = before.rms / after.rms;
        best_k = k;
      }
    }
  std::printf("best K %u: RMS %.2fx lower\n", best_k, best_ratio);
  double automatic_hausdorff = 0;  // one snap at the automatic level
  {
    // --clusters auto: fandisk's curve has no jump, so the level is the tolerance cut at 0.4
    // times the estimated noise on the hierarchy of the bilateral copy (the knee of the curve,
    // K = 23, gave 2.25x).
    Denoiser denoiser(noisy, bilateral_options());
    DenoiseLevel chosen;
    double floor = 0;
    const SnapReport report = denoiser.iterate([&](const Hierarchy& hierarchy) {
      chosen = denoiser.automatic_level(hierarchy);
      EXPECT_EQ(chosen.segmentation.labels, cut_by_tolerance(hierarchy, 0.4 * chosen.noise).labels);
      floor = testing::least_squares_floor(hierarchy, chosen.segmentation, sigma);
      return chosen.segmentation;
    });
    const MeshDistance after = mesh_distance(denoiser.mesh(), clean, measure);
    std::printf("%8s %12.4g %12.4g %8.2f %12s %8.2f   (K = %u: noise %.4g, tolerance %.4g)\n",
                "auto", after.rms, after.hausdorff, before.rms / after.rms, "bilateral",
                before.hausdorff / after.hausdorff, report.clusters, chosen.noise,
                chosen.tolerance);
    EXPECT_TRUE(chosen.by_noise);
    EXPECT_EQ(chosen.automatic.rule, AutoLevelRule::Knee);
    EXPECT_EQ(chosen.jump_worst_rms, 0);   // no jump to judge
    EXPECT_GE(chosen.noise, 0.9 * sigma);  // measured 0.98 sigma
    EXPECT_LE(chosen.noise, 1.05 * sigma);
    EXPECT_EQ(chosen.tolerance, 0.4 * chosen.noise);
    EXPECT_EQ(testing::inverted_triangles(noisy, denoiser.mesh()), 0u);
    EXPECT_LT(after.rms * 3.5, before.rms);  // measured 3.9x (3.8x with independent directions)
    // What the level's primitives leave at least (least_squares_floor): the vertices end within
    // 1.05 floors of the clean surface (seed 7: 1.13), so the ratio is what the level's number of
    // parameters allows, sqrt(V / (2 P)) = 3.8x (seed 7: 37 clusters, 4.5x).
    const double left = testing::vertex_rms_to_surface(denoiser.mesh(), clean);
    std::printf("%8s vertices %.3f floors from the clean surface, ratio bound %.2fx\n", "auto",
                left / floor, sigma / std::sqrt(2.0) / floor);
    EXPECT_LE(left, 1.2 * floor);
    automatic_hausdorff = after.hausdorff;
  }
  {
    // The target, 5x, is where even the clean segmentation ends with independent primitives:
    // snapped onto the clean mesh's own level of 30 clusters (129 parameters for 6,475
    // vertices), the vertices reach the floor (0.96 floors) and the RMS drops 5.5x (seed 7:
    // 5.3x) against a bound of 5.0x. Each cluster more costs 3 to 5 parameters, each surface
    // missed costs bias; a noisy segmentation has both. Relations between the primitives (the
    // default: parallel directions, coaxial cylinders) spend fewer: 6.3x.
    const Hierarchy truth = build_hierarchy(std::make_shared<const Mesh>(clean));
    const Segmentation level = cut_by_count(truth, 30);
    DenoiseOptions independent;
    independent.relation_significance = 0;
    Denoiser denoiser(noisy, independent);
    denoiser.snap(truth, level);
    const double floor = testing::least_squares_floor(truth, level, sigma);
    const double left = testing::vertex_rms_to_surface(denoiser.mesh(), clean);
    const MeshDistance after = mesh_distance(denoiser.mesh(), clean, measure);
    std::printf("%8s %12.4g %12.4g %8.2f %12s %8.2f   (%.3f floors left, ratio bound %.2fx)\n",
                "clean 30", after.rms, after.hausdorff, before.rms / after.rms, "oracle",
                before.hausdorff / after.hausdorff, left / floor, sigma / std::sqrt(2.0) / floor);
    EXPECT_LE(left, 1.1 * floor);
    EXPECT_GE(before.rms / after.rms, 5.0);
    EXPECT_LE(before.rms / after.rms, 6.0);

    Denoiser related(noisy);
    related.snap(truth, level);
    const MeshDistance shared = mesh_distance(related.mesh(), clean, measure);
    std::printf("%8s %12.4g %12.4g %8.2f %12s %8.2f\n", "clean 30", shared.rms, shared.hausdorff,
                before.rms / shared.rms, "relations", before.hausdorff / shared.hausdorff);
    EXPECT_GE(before.rms / shared.rms, 1.1 * before.rms / after.rms);  // measured 1.15
  }
  {
    // Stylization keeps the segmentation's automatic level: the knee, few clusters.
    DenoiseOptions options = bilateral_options();
    options.mode = SnapMode::NearestIncident;
    Denoiser denoiser(noisy, options);
    denoiser.iterate([&](const Hierarchy& hierarchy) {
      const DenoiseLevel chosen = denoiser.automatic_level(hierarchy);
      EXPECT_FALSE(chosen.by_noise);
      EXPECT_EQ(chosen.segmentation.labels,
                cut_by_count(hierarchy, choose_level(hierarchy).clusters).labels);
      return chosen.segmentation;
    });
  }
  // One snap: 3.6x (bilateral smoothing, K = 60), 2.7x (5 Taubin steps, K = 60); without
  // smoothing, noise fragments the segmentation into small planes and the gain is at most 1.8x.
  // Snapping the same noisy vertices onto the clean mesh's segmentation gives 5.5x at K = 30
  // (above): the gap is the segmentation of the noisy curved parts, and the parameters its extra
  // clusters cost (see docs/method.md).
  EXPECT_GE(best_ratio, 3.3);

  // The target, 5x at the automatic level and at the best of K = 20, 30, 40, 60, with the
  // ensemble (DenoiseOptions::ensemble_members): the mean of the snaps onto 16 hierarchies, the
  // further ones built on copies jittered before smoothing, each misplacing other faces.
  // Measured 5.25x at the automatic level and 5.02x at K = 30 (five noise draws: 5.21x to 5.53x
  // and 4.95x to 5.45x).
  Mesh ensemble_automatic;
  SnappedLevel ensemble_level;
  {
    DenoiseOptions options = bilateral_options();
    options.ensemble_members = 16;
    double best_ensemble = 0;
    for (const std::uint32_t k : {20u, 30u, 40u, 60u, 0u}) {
      Denoiser denoiser(noisy, options);
      const SnapReport report = denoiser.iterate([&](const Hierarchy& hierarchy) {
        return k ? cut_by_count(hierarchy, k) : denoiser.automatic_level(hierarchy).segmentation;
      });
      const MeshDistance after = mesh_distance(denoiser.mesh(), clean, measure);
      const std::string name = k ? std::to_string(k) : "auto";
      std::printf("%8s %12.4g %12.4g %8.2f %12s %8.2f   (K = %u, %u reverted)\n", name.c_str(),
                  after.rms, after.hausdorff, before.rms / after.rms, "ensemble 16",
                  before.hausdorff / after.hausdorff, report.clusters, report.reverted);
      EXPECT_EQ(testing::inverted_triangles(noisy, denoiser.mesh()), 0u);
      EXPECT_EQ(report.ensemble_members, 16u);
      if (k) {
        best_ensemble = std::max(best_ensemble, before.rms / after.rms);
        continue;
      }
      EXPECT_GE(before.rms / after.rms, 5.0);
      EXPECT_LT(after.hausdorff, automatic_hausdorff);  // measured 0.0070 against 0.0119
      ensemble_automatic = denoiser.mesh();
      ensemble_level = denoiser.snapped_level();
    }
    EXPECT_GE(best_ensemble, 5.0);
  }

  if (const char* figures = std::getenv("PRIMSEG_FIGURES_DIR")) {
    const std::filesystem::path dir(figures);
    RenderOptions view;
    view.width = 600;
    view.height = 450;
    view.view_direction = {-1.0, -0.6, -0.9};
    Vec3 low = clean.positions[0], high = clean.positions[0];
    for (const Vec3& p : clean.positions)
      for (int d = 0; d < 3; ++d) {
        low[d] = std::min(low[d], p[d]);
        high[d] = std::max(high[d], p[d]);
      }
    view.frame_box = {{low, high}};
    for (const auto& [name, mesh] :
         {std::pair<const char*, const Mesh*>{"fandisk-clean.png", &clean},
          {"fandisk-noisy.png", &noisy},
          {"fandisk-denoised.png", &ensemble_automatic}})
      write_png(dir / name, *mesh, {}, view);
    // The automatic level's clusters on its denoised mesh, where they meet drawn: the feature
    // lines the snap recovered (`denoise --ensemble 16 --png`).
    view.borders = true;
    write_png(dir / "fandisk-feature-lines.png", ensemble_automatic,
              group_face_colors(ensemble_level.labels), view);
  }
}

}  // namespace
}  // namespace primseg
