#include <cstdio>
#include <memory>

#include "command.hpp"
#include "limits.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_distance.hpp"
#include "primseg/mesh_io.hpp"

namespace primseg::cli {
namespace {

nlohmann::json one_side(const OneSidedDistance& d, double diagonal) {
  const double percent = diagonal > 0 ? 100 / diagonal : 0;
  return {{"mean", d.mean},
          {"rms", d.rms},
          {"max", d.max},
          {"samples", d.samples},
          {"mean_percent", d.mean * percent},
          {"rms_percent", d.rms * percent},
          {"max_percent", d.max * percent}};
}

}  // namespace

Command add_distance_command(CLI::App& app) {
  struct Options {
    std::string first, second;
    std::optional<std::uint64_t> samples;
    std::optional<double> density;
    std::uint64_t seed = DistanceOptions{}.seed;
    unsigned threads = 0;
    std::optional<std::string> json;
    bool quiet = false;
    ResourceLimits limits;
  };
  auto o = std::make_shared<Options>();
  auto* distance = app.add_subcommand(
      "distance", "Metro-style distances between two surfaces: mean, RMS and Hausdorff");
  distance->add_option("A", o->first, "First mesh (- for standard input)")->required();
  distance->add_option("B", o->second, "Second mesh (- for standard input)")->required();
  auto* samples = distance->add_option("--samples", o->samples,
                                       "Area-uniform samples on each surface (default " +
                                           std::to_string(DistanceOptions{}.samples) + ")");
  auto* density =
      distance->add_option("--density", o->density, "Samples per unit area instead of a count");
  samples->excludes(density);
  distance->add_option("--seed", o->seed, "Seed of the sample positions")->capture_default_str();
  distance->add_option("--threads", o->threads, "Threads for the queries (0: all cores)")
      ->capture_default_str();
  distance->add_option("--json", o->json, "Write the figures as JSON (- for standard output)");
  distance->add_flag("--quiet,-q", o->quiet, "No table on standard output");
  add_limit_options(*distance, o->limits, kMeshBytesPerFace);

  return {distance, [o] {
            DistanceOptions options;
            if (o->samples) options.samples = *o->samples;
            if (o->density) options.density = *o->density;
            options.seed = o->seed;
            options.threads = o->threads;
            if (o->first == kStandardInput && o->second == kStandardInput)
              throw InvalidInputError("distance: only one of A and B can be standard input ('-')");
            std::uint64_t bytes_a = 0, bytes_b = 0;
            const Mesh a = read_geometry(o->first, &bytes_a, o->limits.max_memory);
            const Mesh b = read_geometry(o->second, &bytes_b, o->limits.max_memory);
            check_mesh_limits({&a, &b}, bytes_a + bytes_b, o->limits);
            const auto start = Clock::now();
            const MeshDistance d = mesh_distance(a, b, options);
            const double seconds = seconds_since(start);
            const nlohmann::json json = {
                {"a", o->first},
                {"b", o->second},
                {"bbox_diagonal", d.diagonal},
                {"a_to_b", one_side(d.a_to_b, d.diagonal)},
                {"b_to_a", one_side(d.b_to_a, d.diagonal)},
                {"symmetric",
                 one_side({d.mean, d.rms, d.hausdorff, d.a_to_b.samples + d.b_to_a.samples},
                          d.diagonal)},
                {"seed", o->seed},
                {"timing", {{"seconds", seconds}}}};
            if (o->json) write_output(*o->json, json.dump(2) + "\n");
            if (o->quiet || o->json == kStandardOutput) return;
            const double percent = d.diagonal > 0 ? 100 / d.diagonal : 0;
            std::printf("bounding-box diagonal %.6g; %llu + %llu samples\n", d.diagonal,
                        static_cast<unsigned long long>(d.a_to_b.samples),
                        static_cast<unsigned long long>(d.b_to_a.samples));
            std::printf("%-10s %13s %13s %13s %9s %9s %9s\n", "", "mean", "rms", "hausdorff",
                        "mean %", "rms %", "max %");
            auto row = [&](const char* name, double mean, double rms, double max) {
              std::printf("%-10s %13.6g %13.6g %13.6g %9.4f %9.4f %9.4f\n", name, mean, rms, max,
                          mean * percent, rms * percent, max * percent);
            };
            row("A -> B", d.a_to_b.mean, d.a_to_b.rms, d.a_to_b.max);
            row("B -> A", d.b_to_a.mean, d.b_to_a.rms, d.b_to_a.max);
            row("symmetric", d.mean, d.rms, d.hausdorff);
          }};
}

}  // namespace primseg::cli
