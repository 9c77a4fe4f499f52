// primseg batch: segments every mesh of a directory or a list with N worker threads. Each file's
// outputs are written atomically (labels, then the JSON, whose presence marks the file done), so
// an interrupted run loses nothing finished and --resume picks up where it stopped; one bad file
// is a line in the summary report, never the end of the run. --shard i/n takes every n-th file
// from the i-th on (sorted order), so machines can split a data set without coordination.

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <new>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "../src/file_io.hpp"
#include "../src/parallel.hpp"
#include "command.hpp"
#include "limits.hpp"
#include "primseg/error.hpp"
#include "primseg/mesh_io.hpp"

namespace primseg::cli {
namespace {

namespace fs = std::filesystem;

struct BatchOptions {
  std::string input, out, shard, primitives = "plane,cylinder,sphere", weights = "area";
  unsigned jobs = 0;
  bool resume = false, exact_costs = false, quiet = false;
  double merge_batch_tolerance = 0;
  LevelChoice level;
  LevelOptions fit;  // --refine, --regularize and its options only
  ResourceLimits limits;
};

struct Item {
  fs::path input;
  std::string key;  // output name under --out, without extension
};

struct Result {
  std::string status;  // ok, failed, skipped
  std::string error;
  std::uint32_t faces = 0;
  double seconds = 0;
};

bool is_mesh_path(const fs::path& path) {
  try {
    mesh_format_from_path(path);
    return true;
  } catch (const InvalidInputError&) {
    return false;
  }
}

/// An output key that stays under --out: no root, no "..".
std::string key_for(const fs::path& relative) {
  std::string key;
  for (const fs::path& part : relative.lexically_normal().relative_path()) {
    const std::string name = part == ".." ? std::string("_up_") : part.string();
    if (name.empty() || name == ".") continue;
    key += (key.empty() ? "" : "/") + name;
  }
  return key;
}

std::vector<Item> collect_inputs(const fs::path& input) {
  std::vector<Item> items;
  std::error_code error;
  const bool standard_input = is_standard_input(input);
  if (!standard_input && fs::is_directory(input, error)) {
    for (auto it = fs::recursive_directory_iterator(input, error); !error && it != fs::end(it);
         it.increment(error))
      if (it->is_regular_file() && is_mesh_path(it->path()))
        items.push_back({it->path(), key_for(it->path().lexically_relative(input))});
    if (error) detail::io_failure(input, "list", error.value());
  } else {
    // A list of paths on standard input (`find ... | primseg batch -`), relative to the working
    // directory as a list file's are.
    const detail::FileImage list =
        standard_input ? detail::read_standard_input() : detail::read_file(input);
    const std::string_view text = list.view();
    std::size_t begin = 0;
    while (begin < text.size()) {
      std::size_t end = text.find('\n', begin);
      if (end == std::string_view::npos) end = text.size();
      std::string line(text.substr(begin, end - begin));
      begin = end + 1;
      while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
      if (line.empty() || line[0] == '#') continue;
      items.push_back({line, key_for(line)});
    }
  }
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.key < b.key; });
  items.erase(std::unique(items.begin(), items.end(),
                          [](const Item& a, const Item& b) { return a.input == b.input; }),
              items.end());
  for (std::size_t i = 1; i < items.size(); ++i)
    if (items[i].key == items[i - 1].key)
      throw InvalidInputError("'" + items[i - 1].input.string() + "' and '" +
                              items[i].input.string() + "' would write the same outputs");
  if (items.empty())
    throw InvalidInputError((standard_input ? input_name(input) : "'" + input.string() + "'") +
                            ": no mesh files to process");
  return items;
}

/// "i/n" with 0 <= i < n; {0, 1} when empty.
std::pair<std::size_t, std::size_t> parse_shard(const std::string& text) {
  if (text.empty()) return {0, 1};
  std::size_t index = 0, count = 0;
  int used = 0;
  if (std::sscanf(text.c_str(), "%zu/%zu%n", &index, &count, &used) != 2 ||
      static_cast<std::size_t>(used) != text.size() || count == 0 || index >= count)
    throw InvalidInputError("--shard: '" + text + "' is not i/n with 0 <= i < n");
  return {index, count};
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

/// The options that decide a file's outputs: a completed output made with others is redone.
std::string options_signature(const BatchOptions& o) {
  return "primitives=" + o.primitives + " weights=" + o.weights +
         " exact_costs=" + (o.exact_costs ? "1" : "0") +
         " clusters=" + o.level.clusters.value_or("-") +
         " tolerance=" + o.level.tolerance.value_or(kDefaultTolerance) +
         // Only when set, so that outputs made before these options existed still resume.
         (o.merge_batch_tolerance > 0
              ? " merge_batch_tolerance=" + nlohmann::json(o.merge_batch_tolerance).dump()
              : "") +
         (o.fit.refine > 0 ? " refine=" + std::to_string(o.fit.refine) : "") +
         (o.fit.regularize ? " regularize=1" + relation_options_signature(o.fit.relations) : "");
}

/// Faces recorded in a complete output made with the same options, or nothing.
std::optional<std::uint32_t> completed_faces(const fs::path& json_path, const fs::path& labels,
                                             const std::string& signature) {
  std::error_code error;
  if (!fs::exists(json_path, error) || !fs::exists(labels, error)) return std::nullopt;
  try {
    const detail::FileImage image = detail::read_file(json_path);
    const nlohmann::json json = nlohmann::json::parse(image.view());
    if (json.value("batch_options", std::string()) != signature) return std::nullopt;
    return json.at("mesh").at("faces").get<std::uint32_t>();
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

class ProgressBar {
 public:
  ProgressBar(std::size_t total, bool quiet) : total_(total), enabled_(!quiet && ::isatty(2)) {}

  void update(std::size_t done, std::size_t failed) const {
    if (!enabled_) return;
    const double elapsed = seconds_since(start_);
    const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0;
    const double eta = rate > 0 ? static_cast<double>(total_ - done) / rate : 0;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(kWidth * done / std::max<std::size_t>(total_, 1));
    std::fprintf(stderr, "\r[%s%s] %zu/%zu, %zu failed, %.2f files/s, ETA %d:%02d ",
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(kWidth - filled), '.').c_str(), done, total_,
                 failed, rate, static_cast<int>(eta) / 60, static_cast<int>(eta) % 60);
    if (done == total_) std::fprintf(stderr, "\n");
  }

 private:
  std::size_t total_;
  bool enabled_;
  Clock::time_point start_ = Clock::now();
};

Result process(const Item& item, const BatchOptions& o, const HierarchyOptions& options,
               const std::string& signature) {
  const auto start = Clock::now();
  Result result;
  const fs::path base = fs::path(o.out) / item.key;
  LevelOptions level;
  level.level = o.level;
  level.refine = o.fit.refine;
  level.regularize = o.fit.regularize;
  level.relations = o.fit.relations;
  level.quiet = true;
  level.files.labels = base.string() + ".labels";
  level.files.json = base.string() + ".json";
  if (o.resume) {
    if (const auto faces = completed_faces(*level.files.json, *level.files.labels, signature)) {
      result.status = "skipped";
      result.faces = *faces;
      return result;
    }
  }
  try {
    auto mesh = std::make_shared<const Mesh>(read_geometry_within(item.input, o.limits));
    result.faces = mesh->face_count();
    validate_level(o.level, mesh->face_count());
    detail::create_directories(base.parent_path());
    const Hierarchy hierarchy = build_hierarchy(mesh, options);
    nlohmann::json summary;
    summary["mesh"] = mesh_summary(item.input.string(), hierarchy);
    summary["batch_options"] = signature;
    report_level(hierarchy, level, summary, Clock::now());
    result.status = "ok";
  } catch (const Error& e) {
    result = {"failed", e.what(), result.faces, 0};
  } catch (const std::bad_alloc&) {
    result = {"failed", "out of memory", result.faces, 0};
  } catch (const std::exception& e) {
    result = {"failed", std::string("internal error: ") + e.what(), result.faces, 0};
  }
  result.seconds = seconds_since(start);
  return result;
}

void write_reports(const std::vector<Item>& items, const std::vector<Result>& results,
                   const fs::path& base) {
  std::string csv = "file,faces,status,error,seconds\n";
  nlohmann::json json = nlohmann::json::array();
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Result& r = results[i];
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.3f", r.seconds);
    csv += csv_field(items[i].input.string()) + "," + std::to_string(r.faces) + "," + r.status +
           "," + csv_field(r.error) + "," + seconds + "\n";
    json.push_back({{"file", items[i].input.string()},
                    {"faces", r.faces},
                    {"status", r.status},
                    {"error", r.error},
                    {"seconds", r.seconds}});
  }
  detail::write_file_atomically(base.string() + ".csv", csv);
  detail::write_file_atomically(
      base.string() + ".json",
      json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

void run_batch(const BatchOptions& o) {
  HierarchyOptions options;
  options.primitives = parse_primitives(o.primitives);
  options.weights = o.weights == "uniform" ? VertexWeights::Uniform : VertexWeights::Area;
  options.exact_costs = o.exact_costs;
  options.merge_batch_tolerance = o.merge_batch_tolerance;
  options.threads = 1;  // The workers are the parallelism: one file each.
  validate(options);
  validate_relation_options(o.fit.relations);
  validate_level(o.level, UINT32_MAX);
  const auto [shard, shards] = parse_shard(o.shard);

  std::vector<Item> items;
  {
    std::vector<Item> all = collect_inputs(o.input);
    for (std::size_t i = shard; i < all.size(); i += shards) items.push_back(std::move(all[i]));
  }
  detail::create_directories(o.out);
  const std::string signature = options_signature(o);
  std::vector<Result> results(items.size());
  std::atomic<std::size_t> next{0};
  std::mutex progress_mutex;
  std::size_t done = 0, failed = 0;
  const ProgressBar bar(items.size(), o.quiet);
  bar.update(0, 0);
  const auto worker = [&] {
    for (std::size_t i = next++; i < items.size(); i = next++) {
      results[i] = process(items[i], o, options, signature);
      const std::lock_guard lock(progress_mutex);
      ++done;
      failed += results[i].status == "failed";
      bar.update(done, failed);
    }
  };
  const unsigned jobs = detail::thread_count(o.jobs);
  std::vector<std::thread> threads;
  const auto workers = static_cast<unsigned>(std::min<std::size_t>(jobs, items.size()));
  threads.reserve(workers);
  detail::start_threads(threads, workers, [&worker](unsigned) { worker(); });
  worker();
  for (std::thread& t : threads) t.join();

  const std::string report_name =
      shards == 1 ? "summary"
                  : "summary-shard-" + std::to_string(shard) + "-of-" + std::to_string(shards);
  write_reports(items, results, fs::path(o.out) / report_name);
  const auto skipped = static_cast<std::size_t>(std::count_if(
      results.begin(), results.end(), [](const Result& r) { return r.status == "skipped"; }));
  if (!o.quiet)
    std::printf("%s: %zu ok, %zu skipped, %zu failed; report %s.csv\n",
                count_of(items.size(), "file").c_str(), items.size() - failed - skipped, skipped,
                failed, (fs::path(o.out) / report_name).c_str());
  if (failed)
    throw InvalidInputError(std::to_string(failed) + " of " + count_of(items.size(), "file") +
                            " failed (see " + (fs::path(o.out) / report_name).string() + ".csv)");
}

}  // namespace

Command add_batch_command(CLI::App& app) {
  auto o = std::make_shared<BatchOptions>();
  auto* batch = app.add_subcommand(
      "batch", "Segment every mesh of a directory (recursively) or a list file, in parallel");
  batch
      ->add_option("INPUT_DIR_OR_LIST", o->input,
                   "Directory of .off .obj .ply .stl files, or a text file with one path per line "
                   "(- for standard input)")
      ->required();
  batch
      ->add_option("--out", o->out,
                   "Output directory: <name>.labels and <name>.json per input, "
                   "summary.csv and summary.json")
      ->required();
  batch->add_option("-j,--jobs", o->jobs, "Worker threads (0: all cores)")->capture_default_str();
  batch->add_flag("--resume", o->resume,
                  "Skip inputs whose outputs are complete (made with the same options)");
  batch->add_option("--shard", o->shard,
                    "Process only shard i of n (0 <= i < n): every n-th input of the sorted "
                    "list, from the i-th");
  auto* clusters = batch->add_option("--clusters", o->level.clusters, "Number of clusters K");
  batch
      ->add_option("--tolerance", o->level.tolerance,
                   std::string("Largest RMS distance of a cluster, in input units or T% of the "
                               "bounding-box diagonal (default ") +
                       kDefaultTolerance + ")")
      ->excludes(clusters);
  batch->add_option("--primitives", o->primitives, "Primitive types, comma-separated")
      ->capture_default_str();
  batch->add_option("--weights", o->weights, "Vertex weights of the fitting error")
      ->check(CLI::IsMember({"area", "uniform"}))
      ->capture_default_str();
  batch->add_flag("--exact-costs", o->exact_costs, "Reference mode: exact Euclidean errors");
  add_merge_batch_option(*batch, o->merge_batch_tolerance);
  add_fit_options(*batch, o->fit);
  add_limit_options(*batch, o->limits, kHierarchyBytesPerFace);
  batch->add_flag("--quiet,-q", o->quiet, "No progress or summary output");
  return {batch, [o] { run_batch(*o); }};
}

}  // namespace primseg::cli
