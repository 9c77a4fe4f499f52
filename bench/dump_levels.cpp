// primseg_dump_levels: writes the labels of several levels of the default hierarchy of fandisk
// and of every generated shape (CAD, uniform and noisy tessellations), one file per level, for
// bench/compare_revisions.sh to compare two builds of primseg. Uses the public API only, so that
// the same source builds against any revision.
//
// Levels: fandisk at K = 10, 20, 30, 60, 100; every shape at its true number of regions, and the
// noisy ones also at twice that and at 20. Finer levels of the clean shapes are left out: they
// split exactly fitting regions, where symmetric candidates cost the same up to round-off and
// any change of solver picks another of them (a different but equally valid split).
//
//   primseg_dump_levels OUT_DIR FANDISK_OFF
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "primseg/cut.hpp"
#include "primseg/hierarchy.hpp"
#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"

namespace {

void dump(const std::filesystem::path& directory, const std::string& name,
          const primseg::Mesh& mesh, const std::vector<std::uint32_t>& levels) {
  const primseg::Hierarchy tree = primseg::build_hierarchy(mesh);
  for (std::uint32_t k : levels) {
    if (k < 1 || k > tree.face_count()) continue;
    const primseg::Segmentation level = primseg::cut_by_count(tree, k);
    std::ofstream out(directory / (name + "_K" + std::to_string(k) + ".txt"));
    for (std::uint32_t label : level.labels) out << label << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s OUT_DIR FANDISK_OFF\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path out = argv[1];
    std::filesystem::create_directories(out);
    dump(out, "fandisk", primseg::read_mesh(argv[2]), {10, 20, 30, 60, 100});
    for (const std::string& shape : primseg::shape_names())
      for (const char* variant : {"cad", "uniform", "noisy"}) {
        primseg::ShapeOptions options;
        options.tessellation = std::string(variant) == "cad" ? primseg::Tessellation::Cad
                                                             : primseg::Tessellation::Uniform;
        if (std::string(variant) == "noisy") options.noise = 0.002;
        options.random_motion = true;
        const primseg::GroundTruthShape generated = primseg::make_shape(shape, options);
        std::uint32_t regions = 0;
        for (std::uint32_t r : generated.region_of_face) regions = std::max(regions, r + 1);
        if (options.noise > 0)
          dump(out, shape + "_" + variant, generated.mesh, {regions, 2 * regions, 20});
        else
          dump(out, shape + "_" + variant, generated.mesh, {regions});
      }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
