// End-to-end tests of `primseg batch`, the resource limits of every command and interruption: run
// the built executable, check exit codes, output files and reports.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "primseg/mesh_io.hpp"
#include "primseg/shape_generator.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Paths in these tests come from temp_directory() and fixed names: no shell quoting needed
// beyond single quotes.
int primseg(const std::string& args, std::string* output = nullptr) {
  // Appended piecewise: `"'" + string` trips a false -Wrestrict in g++ 12 release builds.
  std::string command(1, '\'');
  command.append(testing::cli_path().string()).append("' ").append(args);
  return testing::run_command(command, output);
}

/// Rows of a summary CSV (header checked), keyed by file: "faces,status".
std::map<std::string, std::string> summary_rows(const fs::path& csv) {
  std::istringstream in(testing::file_contents(csv));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "file,faces,status,error,seconds") << csv;
  std::map<std::string, std::string> rows;
  while (std::getline(in, line)) {
    const std::size_t first = line.find(','), second = line.find(',', first + 1),
                      third = line.find(',', second + 1);
    rows[line.substr(0, first)] = line.substr(first + 1, third - first - 1);
  }
  return rows;
}

/// The status of a summary row ("faces,status").
std::string status_of(const std::string& row) {
  return row.substr(row.find(',') + 1);
}

/// Expects every file of a summary CSV to have `status` ("ok", "skipped").
void expect_every_status(const fs::path& csv, const std::string& status) {
  for (const auto& [file, row] : summary_rows(csv)) EXPECT_EQ(status_of(row), status) << file;
}

/// Every file under `dir` but the summaries, relative, with its content (JSON without timings).
std::map<std::string, std::string> outputs(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = entry.path().lexically_relative(dir).string();
    if (name.starts_with("summary")) continue;
    std::string content = testing::file_contents(entry.path());
    if (entry.path().extension() == ".json") {
      json parsed = json::parse(content);
      parsed.erase("timing");
      content = parsed.dump();
    }
    files[name] = content;
  }
  return files;
}

/// A data set: four shapes (one in a subfolder) and a file that is not a mesh.
fs::path make_data_set(const fs::path& root) {
  const fs::path in = root / "in";
  fs::create_directories(in / "parts");
  write_mesh(in / "box.off", make_shape("box").mesh);
  write_mesh(in / "parts" / "hole.ply", make_shape("box_with_hole").mesh);
  write_mesh(in / "dome.obj", make_shape("box_with_dome").mesh);
  write_mesh(in / "boss.stl", make_shape("box_with_boss").mesh);
  std::ofstream(in / "broken.off") << "OFF\n3 1 0\n0 0 0\n1 0 0\n";
  std::ofstream(in / "readme.txt") << "not a mesh, not listed\n";
  return in;
}

TEST(Batch, OneBadFileIsReportedAndDoesNotStopTheOthers) {
  const fs::path dir = testing::temp_directory("batch-bad");
  const fs::path in = make_data_set(dir);
  std::string output;
  EXPECT_EQ(primseg("batch '" + in.string() + "' --out '" + (dir / "out").string() +
                        "' -j 2 --clusters 6 2>&1",
                    &output),
            1)
      << output;
  EXPECT_NE(output.find("1 of 5 files failed"), std::string::npos) << output;
  const auto rows = summary_rows(dir / "out" / "summary.csv");
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows.at((in / "broken.off").string()), "0,failed");
  EXPECT_EQ(rows.at((in / "box.off").string()),
            std::to_string(make_shape("box").mesh.face_count()) + ",ok");
  for (const char* name : {"box.off", "parts/hole.ply", "dome.obj", "boss.stl"})
    EXPECT_EQ(status_of(rows.at((in / name).string())), "ok") << name;
  // The failure's message names the file and the problem.
  const json report = json::parse(testing::file_contents(dir / "out" / "summary.json"));
  ASSERT_EQ(report.size(), 5u);
  for (const json& row : report)
    if (row["status"] == "failed") {
      EXPECT_NE(row["error"].get<std::string>().find("broken.off"), std::string::npos);
    }
  // Batch outputs are exactly what `segment` gives for the same file and options.
  ASSERT_EQ(primseg("segment '" + (in / "parts" / "hole.ply").string() +
                    "' -q --clusters 6 --labels '" + (dir / "hole.labels").string() + "'"),
            0);
  EXPECT_EQ(testing::file_contents(dir / "out" / "parts" / "hole.ply.labels"),
            testing::file_contents(dir / "hole.labels"));
  EXPECT_FALSE(fs::exists(dir / "out" / "broken.off.json"));
  fs::remove_all(dir);
}

// --refine and --regularize as `segment` takes them: the same JSON clusters and relations per
// file, and a resumed run with other fit options redoes every file.
TEST(Batch, RefinedAndRegularizedOutputsAreSegments) {
  const fs::path dir = testing::temp_directory("batch-fit");
  const fs::path in = make_data_set(dir);
  fs::remove(in / "broken.off");
  const std::string base = "batch '" + in.string() + "' --out '" + (dir / "out").string() +
                           "' -q --clusters 7 --refine 2";
  ASSERT_EQ(primseg(base + " --regularize"), 0);
  ASSERT_EQ(primseg("segment '" + (in / "parts" / "hole.ply").string() +
                    "' -q --clusters 7 --refine 2 --regularize --json '" +
                    (dir / "hole.json").string() + "'"),
            0);
  json batch = json::parse(testing::file_contents(dir / "out" / "parts" / "hole.ply.json"));
  json segment = json::parse(testing::file_contents(dir / "hole.json"));
  ASSERT_TRUE(batch.contains("relations"));
  EXPECT_FALSE(batch["relations"].empty());
  EXPECT_EQ(batch["relations"], segment["relations"]);
  EXPECT_EQ(batch["clusters"], segment["clusters"]);
  EXPECT_EQ(batch["level"]["refinement"], segment["level"]["refinement"]);
  // Without --regularize the outputs differ, and --resume does not take the old ones for them.
  ASSERT_EQ(primseg(base + " --resume"), 0);
  expect_every_status(dir / "out" / "summary.csv", "ok");
  batch = json::parse(testing::file_contents(dir / "out" / "parts" / "hole.ply.json"));
  EXPECT_FALSE(batch.contains("relations"));
  // The options of --regularize are the outputs' too: a resumed run with others redoes them.
  ASSERT_EQ(primseg(base + " --regularize"), 0);
  ASSERT_EQ(primseg(base + " --regularize --max-relation-angle 5 --resume"), 0);
  expect_every_status(dir / "out" / "summary.csv", "ok");
  batch = json::parse(testing::file_contents(dir / "out" / "parts" / "hole.ply.json"));
  EXPECT_NE(batch["batch_options"].get<std::string>().find("max_relation_angle=5"),
            std::string::npos);
  // A length tolerance in percent is each file's own length, as `segment` takes it; the
  // percentage is the outputs' option, so that resuming with another redoes them.
  ASSERT_EQ(primseg(base + " --regularize --relation-length-tolerance 0.5%"), 0);
  ASSERT_EQ(primseg("segment '" + (in / "parts" / "hole.ply").string() +
                    "' -q --clusters 7 --refine 2 --regularize --relation-length-tolerance 0.5% "
                    "--json '" +
                    (dir / "hole.json").string() + "'"),
            0);
  batch = json::parse(testing::file_contents(dir / "out" / "parts" / "hole.ply.json"));
  segment = json::parse(testing::file_contents(dir / "hole.json"));
  EXPECT_EQ(batch["relations"], segment["relations"]);
  EXPECT_EQ(batch["clusters"], segment["clusters"]);
  EXPECT_NE(batch["batch_options"].get<std::string>().find("relation_length_tolerance=\"0.5%\""),
            std::string::npos);
  ASSERT_EQ(primseg(base + " --regularize --relation-length-tolerance 0.5% --resume"), 0);
  expect_every_status(dir / "out" / "summary.csv", "skipped");
  ASSERT_EQ(primseg(base + " --regularize --relation-length-tolerance 0.25% --resume"), 0);
  expect_every_status(dir / "out" / "summary.csv", "ok");
  fs::remove_all(dir);
}

TEST(Batch, ResumeSkipsCompletedOutputsAndRedoesTheRest) {
  const fs::path dir = testing::temp_directory("batch-resume");
  const fs::path in = make_data_set(dir);
  fs::remove(in / "broken.off");
  const std::string base = "batch '" + in.string() + "' --out '" + (dir / "out").string() + "' -q";
  ASSERT_EQ(primseg(base + " --clusters 6"), 0);
  const auto first = outputs(dir / "out");
  ASSERT_EQ(first.size(), 8u);
  // An interrupted run: one output missing, another file's JSON (the completion mark) missing.
  fs::remove(dir / "out" / "dome.obj.labels");
  fs::remove(dir / "out" / "parts" / "hole.ply.json");
  const auto box_time = fs::last_write_time(dir / "out" / "box.off.labels");
  ASSERT_EQ(primseg(base + " --clusters 6 --resume"), 0);
  const auto rows = summary_rows(dir / "out" / "summary.csv");
  EXPECT_EQ(status_of(rows.at((in / "box.off").string())), "skipped");
  EXPECT_EQ(status_of(rows.at((in / "boss.stl").string())), "skipped");
  EXPECT_EQ(status_of(rows.at((in / "dome.obj").string())), "ok");
  EXPECT_EQ(status_of(rows.at((in / "parts/hole.ply").string())), "ok");
  EXPECT_EQ(fs::last_write_time(dir / "out" / "box.off.labels"), box_time);
  EXPECT_EQ(outputs(dir / "out"), first);
  // Other options make other outputs: nothing is skipped.
  ASSERT_EQ(primseg(base + " --clusters 4 --resume"), 0);
  expect_every_status(dir / "out" / "summary.csv", "ok");
  // So does another merge order (it makes another tree); resumed with it, they are kept.
  ASSERT_EQ(primseg(base + " --clusters 4 --merge-batch-tolerance 0.1 --resume"), 0);
  expect_every_status(dir / "out" / "summary.csv", "ok");
  ASSERT_EQ(primseg(base + " --clusters 4 --merge-batch-tolerance 0.1 --resume"), 0);
  expect_every_status(dir / "out" / "summary.csv", "skipped");
  fs::remove_all(dir);
}

TEST(Batch, UnionOfShardsEqualsOneRunAndAListEqualsItsDirectory) {
  const fs::path dir = testing::temp_directory("batch-shards");
  const fs::path in = make_data_set(dir);
  const std::string options = " -q --tolerance 0.5% -j 1";
  EXPECT_EQ(
      primseg("batch '" + in.string() + "' --out '" + (dir / "whole").string() + "'" + options), 1);
  std::map<std::string, std::string> union_rows;
  for (int shard = 0; shard < 3; ++shard) {
    primseg("batch '" + in.string() + "' --out '" + (dir / "shards").string() + "' --shard " +
            std::to_string(shard) + "/3" + options);
    const auto rows =
        summary_rows(dir / "shards" / ("summary-shard-" + std::to_string(shard) + "-of-3.csv"));
    EXPECT_GE(rows.size(), 1u);
    for (const auto& [file, row] : rows) EXPECT_TRUE(union_rows.emplace(file, row).second) << file;
  }
  EXPECT_EQ(union_rows, summary_rows(dir / "whole" / "summary.csv"));
  EXPECT_EQ(outputs(dir / "shards"), outputs(dir / "whole"));

  // The recipe of the README: a list of files, relative to the current directory.
  std::ofstream(dir / "list.txt") << "# data set\nin/box.off\nin/parts/hole.ply\n\nin/dome.obj\n"
                                     "in/boss.stl\nin/broken.off\n";
  EXPECT_EQ(testing::run_command("cd '" + dir.string() + "' && '" + testing::cli_path().string() +
                                 "' batch list.txt --out listed" + options),
            1);
  auto listed = outputs(dir / "listed");
  std::map<std::string, std::string> expected;
  for (auto [name, content] : outputs(dir / "whole")) {
    // The listed run names its inputs as listed (relative), under in/.
    if (name.ends_with(".json")) {
      json parsed = json::parse(content);
      parsed["mesh"]["file"] =
          parsed["mesh"]["file"].get<std::string>().substr(dir.string().size() + 1);
      content = parsed.dump();
    }
    expected["in/" + name] = content;
  }
  EXPECT_EQ(listed, expected);
  // The same list on standard input (`find ... | primseg batch -`).
  EXPECT_EQ(testing::run_command("cd '" + dir.string() + "' && '" + testing::cli_path().string() +
                                 "' batch - --out piped" + options + " < list.txt"),
            1);
  EXPECT_EQ(outputs(dir / "piped"), listed);
  fs::remove_all(dir);
}

TEST(Batch, BadArgumentsAreRejectedWithAMessage) {
  const fs::path dir = testing::temp_directory("batch-args");
  const fs::path in = make_data_set(dir);
  const std::string base = "batch '" + in.string() + "' --out '" + (dir / "out").string() + "'";
  // One file listed twice under two spellings of its path: both would write the same outputs.
  std::ofstream(dir / "twice.txt") << (in / "box.off").string() << "\n"
                                   << (in / "." / "box.off").string() << "\n";
  struct Case {
    std::string args, message;
  };
  for (const Case& c : std::vector<Case>{
           {"batch '" + (dir / "twice.txt").string() + "' --out '" + (dir / "out").string() + "'",
            "/box.off' would write the same outputs"},
           {base + " --shard 3/3", "--shard: '3/3' is not i/n"},
           {base + " --shard 1", "--shard: '1' is not i/n"},
           {base + " --primitives ellipsoid", "unknown primitive 'ellipsoid'"},
           {"batch '" + (dir / "missing").string() + "' --out '" + (dir / "out").string() + "'",
            "missing"},
           {"batch '" + (in / "parts").string() + "/..' --out x --max-memory 0", "--max-memory"},
           // A file where the output directory should be: exit 1, not an internal error.
           {"batch '" + in.string() + "' --out '" + (in / "box.off" / "out").string() + "'",
            "cannot create the directory '" + (in / "box.off" / "out").string() +
                "': Not a directory"},
           {"batch - --out '" + (dir / "out").string() + "' < /dev/null",
            "standard input: no mesh files to process"},
       }) {
    std::string output;
    EXPECT_EQ(primseg(c.args + " 2>&1", &output), 1) << c.args << "\n" << output;
    EXPECT_NE(output.find(c.message), std::string::npos) << c.args << "\n" << output;
  }
  const fs::path empty = dir / "empty";
  fs::create_directories(empty);
  std::string output;
  EXPECT_EQ(
      primseg("batch '" + empty.string() + "' --out '" + (dir / "o").string() + "' 2>&1", &output),
      1);
  EXPECT_NE(output.find("no mesh files"), std::string::npos) << output;
  fs::remove_all(dir);
}

TEST(Limits, MaxFacesAndMaxMemoryRefuseBeforeTheBuild) {
  const fs::path dir = testing::temp_directory("limits");
  const Mesh mesh = make_shape("box_with_hole").mesh;
  write_mesh(dir / "in.off", mesh);
  const std::string base = "segment '" + (dir / "in.off").string() + "' -q --labels '" +
                           (dir / "out.labels").string() + "'";
  const std::string faces = std::to_string(mesh.face_count());
  std::string output;
  EXPECT_EQ(
      primseg(base + " --max-faces " + std::to_string(mesh.face_count() - 1) + " 2>&1", &output),
      1);
  EXPECT_NE(output.find("the mesh has " + faces + " faces, more than --max-faces"),
            std::string::npos)
      << output;
  EXPECT_EQ(primseg(base + " --max-memory 100K 2>&1", &output), 1);
  EXPECT_NE(output.find("more than --max-memory 102400"), std::string::npos) << output;
  // Smaller than the file itself: refused before reading.
  EXPECT_EQ(primseg(base + " --max-memory 1K 2>&1", &output), 1);
  EXPECT_NE(output.find("the file has"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "out.labels"));
  EXPECT_EQ(primseg(base + " --max-faces " + faces + " --max-memory 1G"), 0);
  EXPECT_TRUE(fs::exists(dir / "out.labels"));
  for (const char* bad :
       {"--max-memory 12X", "--max-memory -5", "--max-faces 0", "--max-memory 0"}) {
    EXPECT_EQ(primseg(base + " " + bad + " 2>&1", &output), 1) << bad;
    EXPECT_NE(output.find(std::string(bad).substr(0, 11)), std::string::npos) << output;
  }
  fs::remove_all(dir);
}

bool under_address_sanitizer() {
#if defined(__SANITIZE_ADDRESS__)
  return true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  return true;
#else
  return false;
#endif
#else
  return false;
#endif
}

// Runs the CLI with `args` (no shell), its output discarded; returns the exit status, and the peak
// resident memory of the run in bytes in `peak`.
int primseg_peak(const std::vector<std::string>& args, std::uint64_t* peak) {
  std::vector<std::string> arguments = {testing::cli_path().string()};
  arguments.insert(arguments.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return -1;
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid) return -1;
  *peak = static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;  // kilobytes on Linux
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Limits, EveryCommandThatReadsAMeshHasThemAndItsEstimateBoundsItsPeak) {
  const fs::path dir = testing::temp_directory("limits-commands");
  const std::string mesh = testing::cgal_mesh("fandisk.off").string();
  const auto out = [&dir](const char* name) { return (dir / name).string(); };
  ASSERT_EQ(primseg("skeleton '" + mesh + "' --clusters 5 -q -o '" + out("skeleton.json") + "'"),
            0);
  ASSERT_EQ(primseg("segment '" + mesh + "' -q --tree '" + out("fandisk.tree") + "'"), 0);
  std::ofstream(dir / "pose.json") << R"({"rotations": []})";
  // Each command with its heaviest options, its last output last; the estimate is the one
  // --max-memory uses (apps/limits.hpp): kProcessBytes (8 MiB) + the input files' bytes + the
  // command's bytes per face of its meshes + 24 MiB for a picture's buffers (--png) or view's
  // page.
  struct Case {
    std::vector<std::string> args;
    std::uint64_t bytes_per_face;
    std::uint64_t input_bytes;
    std::uint64_t meshes = 1;
    std::uint64_t fixed_bytes = 0;
  };
  const std::uint64_t buffers = 24u << 20;  // a picture's, or view's page
  const std::uint64_t faces = 12946, mesh_bytes = fs::file_size(mesh);
  const std::uint64_t tree_bytes = fs::file_size(dir / "fandisk.tree");
  const std::vector<Case> cases = {
      {{"segment", mesh, "--clusters", "30", "-q", "--tree", out("t.tree"), "--png", out("s.png")},
       1024,
       mesh_bytes,
       1,
       buffers},
      // Two regions' hierarchies built side by side.
      {{"segment", mesh, "--regions", "2", "--threads", "2", "-q", "--tree", out("r.tree")},
       1024,
       mesh_bytes},
      {{"cut", out("fandisk.tree"), "--clusters", "30", "--refine", "3", "-q", "--json",
        out("c.json"), "--png", out("c.png")},
       512,
       tree_bytes,
       1,
       buffers},
      {{"denoise", mesh, "--clusters", "auto", "--bilateral", "--iterations", "2", "-q", "-o",
        out("d.ply")},
       1536,
       mesh_bytes},
      {{"denoise", mesh, "--clusters", "auto", "--regions", "2", "--threads", "2", "-q", "-o",
        out("dr.ply")},
       1536,
       mesh_bytes},
      // Two members' hierarchies built side by side.
      {{"denoise", mesh, "--clusters", "auto", "--bilateral", "--ensemble", "4", "--threads", "2",
        "-q", "-o", out("e.ply")},
       3072,
       mesh_bytes},
      {{"skeleton", mesh, "--clusters", "auto", "-q", "-o", out("s.json"), "--skin-weights",
        out("w.txt")},
       1024,
       mesh_bytes},
      {{"skeleton", mesh, "--clusters", "20", "--regions", "2", "--threads", "2", "-q", "-o",
        out("sr.json")},
       1024,
       mesh_bytes},
      {{"view", mesh, "--skeleton", "-q", "-o", out("v.html")}, 1280, mesh_bytes, 1, buffers},
      {{"distance", mesh, mesh, "-q", "--json", out("distance.json")}, 512, 2 * mesh_bytes, 2},
      {{"info", mesh, "--json", out("info.json")}, 512, mesh_bytes},
      {{"info", mesh, "--noise", "--json", out("noise.json")}, 1024, mesh_bytes},
      {{"deform", mesh, out("skeleton.json"), out("pose.json"), "-q", "-o", out("posed.ply"),
        "--png", out("posed.png")},
       512,
       mesh_bytes,
       1,
       buffers}};
  for (const Case& c : cases) {
    const std::string& name = c.args[0];
    std::string command;
    for (const std::string& arg : c.args) command += "'" + arg + "' ";
    std::string output;
    const int status = primseg(command + "2>&1", &output);
    if (name == "view" && output.find("without the web viewer") != std::string::npos) continue;
    ASSERT_EQ(status, 0) << output;
    const std::string written = c.args[c.args.size() - 1];
    fs::remove(written);

    EXPECT_EQ(primseg(command + "--max-faces 12945 2>&1", &output), 1) << name;
    EXPECT_NE(output.find("the mesh has 12946 faces, more than --max-faces 12945"),
              std::string::npos)
        << output;
    const std::uint64_t estimate =
        (8u << 20) + c.fixed_bytes + c.input_bytes + c.meshes * c.bytes_per_face * faces;
    EXPECT_EQ(primseg(command + "--max-memory " + std::to_string(estimate - 1) + " 2>&1", &output),
              1)
        << name;
    EXPECT_NE(output.find("need about " + std::to_string(estimate) +
                          " bytes, more than "
                          "--max-memory " +
                          std::to_string(estimate - 1)),
              std::string::npos)
        << output;
    EXPECT_FALSE(fs::exists(written)) << name;
    // Smaller than the file itself: refused before reading.
    EXPECT_EQ(primseg(command + "--max-memory 1K 2>&1", &output), 1) << name;
    EXPECT_NE(output.find("the file has"), std::string::npos) << output;

    std::vector<std::string> within = c.args;
    within.insert(within.end(), {"--max-memory", std::to_string(estimate)});
    std::uint64_t peak = 0;
    EXPECT_EQ(primseg_peak(within, &peak), 0) << name;
    EXPECT_TRUE(fs::exists(written)) << name;
    // AddressSanitizer's shadow memory and quarantine are no part of the estimate.
    if (!under_address_sanitizer()) {
      EXPECT_LE(peak, estimate) << name << ": the estimate is no bound of the peak";
    }
  }
  fs::remove_all(dir);
}

TEST(Limits, ThePeakEstimateCountsTheTrianglesOfPolygons) {
  // One face of 10,000 corners: 9,998 triangles to store, read and fit, 1 KB each in the estimate.
  const fs::path dir = testing::temp_directory("limits-polygon");
  std::ofstream off(dir / "disc.off");
  off << "OFF\n10000 1 0\n";
  for (int i = 0; i < 10000; ++i)
    off << std::cos(i * 2 * std::numbers::pi / 10000) << ' '
        << std::sin(i * 2 * std::numbers::pi / 10000) << " 0\n";
  off << 10000;
  for (int i = 0; i < 10000; ++i) off << ' ' << i;
  off << '\n';
  off.close();
  const std::uint64_t estimate = (8u << 20) + fs::file_size(dir / "disc.off") + 1024 * 9998;
  const std::string base = "segment '" + (dir / "disc.off").string() + "' -q --max-memory ";
  std::string output;
  EXPECT_EQ(primseg(base + std::to_string(estimate - 1) + " 2>&1", &output), 1);
  EXPECT_NE(output.find("the mesh has 1 face (9998 triangles), which need about " +
                        std::to_string(estimate) + " bytes"),
            std::string::npos)
      << output;
  EXPECT_EQ(primseg(base + std::to_string(estimate)), 0);
  fs::remove_all(dir);
}

// A shell prefix under which an attempt to allocate for a declared count fails. `ulimit -v` does
// it, but AddressSanitizer reserves terabytes of shadow address space at start and cannot run
// under it; its own cap on one allocation does the same there.
std::string memory_limit_prefix() {
  if (under_address_sanitizer())
    return "ASAN_OPTIONS=abort_on_error=1:max_allocation_size_mb=1000 ";
  return "ulimit -v 1000000; ";
}

TEST(Limits, ImpossibleDeclaredCountsAreRefusedWithoutAllocating) {
  const fs::path dir = testing::temp_directory("limits-counts");
  std::ofstream(dir / "huge.off") << "OFF\n1000000000 2000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  std::ofstream(dir / "huge.ply") << "ply\nformat binary_little_endian 1.0\nelement vertex "
                                     "4000000000\nproperty float x\nproperty float y\nproperty "
                                     "float z\nelement face 1\nproperty list uchar int "
                                     "vertex_indices\nend_header\n";
  for (const char* name : {"huge.off", "huge.ply"}) {
    std::string output;
    // Appended in place: g++ 12 reports a false out-of-bounds copy in a chain of string
    // temporaries here (when a unity build inlines it differently).
    std::string command = memory_limit_prefix();
    command +=
        "'" + testing::cli_path().string() + "' segment '" + (dir / name).string() + "' -q 2>&1";
    EXPECT_EQ(testing::run_command(command, &output), 1) << name;
    EXPECT_NE(output.find(name), std::string::npos) << output;
    EXPECT_EQ(output.find("out of memory"), std::string::npos) << output;
  }
  fs::remove_all(dir);
}

// Standard input has no size: without --max-memory it is read up to an eighth of the memory the
// process may use (no larger mesh could be processed), so an endless pipe of a valid-looking
// mesh stops there instead of filling the memory.
TEST(Limits, AnEndlessPipeStopsAtAnEighthOfTheUsableMemory) {
  if (under_address_sanitizer())
    GTEST_SKIP() << "AddressSanitizer cannot run under ulimit -v, and without it the read is 3 GB";
  std::string output;
  EXPECT_EQ(testing::run_command("ulimit -v 1000000; (printf 'OFF\\n3 1 0\\n'; yes '0 0 0') | '" +
                                     testing::cli_path().string() + "' info - 2>&1",
                                 &output),
            1);
  EXPECT_NE(output.find("standard input: more than 128000000 bytes, the most read without a "
                        "size (1/8 of the 1024000000 bytes of memory this process may use"),
            std::string::npos)
      << output;
  // --max-memory sets the limit instead.
  EXPECT_EQ(testing::run_command("(printf 'OFF\\n3 1 0\\n'; yes '0 0 0') | '" +
                                     testing::cli_path().string() + "' info - --max-memory 1M 2>&1",
                                 &output),
            1);
  EXPECT_NE(output.find("standard input: more than --max-memory 1048576 bytes"), std::string::npos)
      << output;
}

TEST(Interrupt, CtrlCLeavesCompleteOutputsOrNone) {
  const fs::path dir = testing::temp_directory("interrupt");
  const fs::path mesh = testing::cgal_mesh("fandisk.off");
  const std::string command = "'" + testing::cli_path().string() + "' segment '" + mesh.string() +
                              "' -q --clusters 20 --labels '" + (dir / "out.labels").string() +
                              "' --json '" + (dir / "out.json").string() + "' --tree '" +
                              (dir / "out.tree").string() + "' --colored '" +
                              (dir / "out.ply").string() + "'";
  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(testing::run_command(command), 0);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string labels = testing::file_contents(dir / "out.labels"),
                    tree = testing::file_contents(dir / "out.tree");
  int interrupted = 0;
  for (int step = 0; step < 12; ++step) {
    for (const auto& entry : fs::directory_iterator(dir)) fs::remove(entry.path());
    // SIGINT from 30% to 140% of a full run: before, during and after the writes.
    const double delay = seconds * (0.3 + 0.1 * step);
    const int status =
        testing::run_command("timeout -s INT " + std::to_string(delay) + " " + command);
    interrupted += status != 0;
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir))
      names.insert(entry.path().filename().string());
    for (const std::string& name : names)
      EXPECT_TRUE(name == "out.labels" || name == "out.json" || name == "out.tree" ||
                  name == "out.ply")
          << "left behind: " << name;
    if (names.count("out.labels")) {
      EXPECT_EQ(testing::file_contents(dir / "out.labels"), labels);
    }
    if (names.count("out.tree")) {
      EXPECT_EQ(testing::file_contents(dir / "out.tree"), tree);
    }
    if (names.count("out.json")) {
      EXPECT_TRUE(json::accept(testing::file_contents(dir / "out.json")));
    }
    if (names.count("out.ply")) {
      EXPECT_NO_THROW((void)read_mesh(dir / "out.ply"));
    }
  }
  EXPECT_GE(interrupted, 1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace primseg
