// `primseg skeleton` and `primseg deform`, run as a user would, on the stick figure written to a
// file.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "primseg/mesh_io.hpp"
#include "support/stick_figure.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A temp directory holding the stick figure as figure.off (its paths need no shell quoting).
class SkeletonCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::temp_directory("skeleton-cli");
    figure_ = testing::make_stick_figure();
    write_mesh(path("figure.off"), figure_.mesh);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  int run(const std::string& args, std::string* output = nullptr) const {
    return testing::run_command(testing::cli_path().string() + " " + args, output);
  }
  // The figure's skeleton at K = 8 with cylinders and spheres, as skeleton.json.
  json skeleton(const std::string& extra = "") const {
    std::string output;
    EXPECT_EQ(
        run("skeleton " + path("figure.off") + " --clusters 8 --primitives cylinder,sphere -o " +
                path("skeleton.json") + " " + extra,
            &output),
        0)
        << output;
    return json::parse(testing::file_contents(path("skeleton.json")));
  }
  // The joint nearest a point.
  static std::uint32_t nearest_joint(const json& skeleton, const Vec3& p) {
    std::uint32_t best = 0;
    double best_distance = INFINITY;
    for (const json& joint : skeleton["joints"]) {
      const auto q = joint["position"].get<std::vector<double>>();
      const double d = std::hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]);
      if (d < best_distance) {
        best_distance = d;
        best = joint["id"].get<std::uint32_t>();
      }
    }
    return best;
  }

  fs::path dir_;
  testing::StickFigure figure_;
};

TEST_F(SkeletonCli, WritesTheSkeletonAndSkinWeights) {
  const json s = skeleton("--skin-weights " + path("weights.txt"));
  EXPECT_EQ(s["cluster_count"], 8);
  EXPECT_EQ(s["primitives"], "cylinder,sphere");
  EXPECT_EQ(s["joint_rule"], "paper");
  ASSERT_EQ(s["bones"].size(), 8u);
  EXPECT_EQ(s["face_labels"].size(), figure_.mesh.face_count());
  std::size_t sensitive = 0, virtual_joints = 0;
  for (const json& joint : s["joints"]) {
    for (const char* key : {"id", "position", "kind", "visible", "bones"})
      EXPECT_TRUE(joint.contains(key)) << key;
    sensitive += joint["kind"] == "sensitive";
    virtual_joints += joint["kind"] == "virtual";
  }
  EXPECT_EQ(sensitive, 7u);       // head, 2 shoulders, 2 hips, 2 elbows
  EXPECT_EQ(virtual_joints, 5u);  // head top, 2 hands, 2 feet
  for (const json& bone : s["bones"])
    for (const char* key : {"id", "cluster", "joints", "visible", "axis", "radius"})
      EXPECT_TRUE(bone.contains(key)) << key;

  // One line per vertex: "bone weight" pairs summing to 1.
  std::istringstream lines(testing::file_contents(path("weights.txt")));
  std::string line;
  std::uint32_t rows = 0;
  while (std::getline(lines, line)) {
    std::istringstream fields(line);
    std::uint32_t bone = 0;
    double weight = 0, sum = 0;
    while (fields >> bone >> weight) {
      EXPECT_LT(bone, 8u);
      sum += weight;
    }
    EXPECT_NEAR(sum, 1, 1e-12) << "line " << rows + 1;
    ++rows;
  }
  EXPECT_EQ(rows, figure_.mesh.vertex_count());
}

// --joints limbs: the figure's torso is one cluster, so every limb already turns where it is
// attached and the skeleton is the paper rule's (limb_joints_test.cpp tests where they differ).
TEST_F(SkeletonCli, LimbJointsAreRecordedAndAgreeWhereThePapersRuleFreesEveryLimb) {
  const json paper = skeleton();
  const json limbs = skeleton("--joints limbs");
  EXPECT_EQ(limbs["joint_rule"], "limbs");
  EXPECT_EQ(limbs["joints"], paper["joints"]);
  EXPECT_EQ(limbs["bones"], paper["bones"]);
}

// The rigged mesh as GLB (read in depth by skeleton_gltf_test.cpp and web/test/gltf.test.mjs).
TEST_F(SkeletonCli, WritesTheRiggedMeshAsGltf) {
  const json s = skeleton("-q --gltf " + path("figure.glb") + " --max-influences 1");
  const std::string glb = testing::file_contents(path("figure.glb"));
  ASSERT_GE(glb.size(), 20u);
  EXPECT_EQ(glb.substr(0, 4), "glTF");
  std::uint32_t json_length = 0;
  std::memcpy(&json_length, glb.data() + 12, 4);
  const json gltf = json::parse(glb.substr(20, json_length));
  std::size_t bones = 0;
  for (const json& node : gltf["nodes"])
    bones += node.contains("extras") && node["extras"].contains("bone");
  EXPECT_EQ(bones, s["bones"].size());
  // One bone per vertex: a single set of joints.
  const json& attributes = gltf["meshes"][0]["primitives"][0]["attributes"];
  EXPECT_TRUE(attributes.contains("WEIGHTS_0"));
  EXPECT_FALSE(attributes.contains("WEIGHTS_1"));

  std::string output;
  EXPECT_NE(run("skeleton " + path("figure.off") + " --clusters 8 -o " + path("s.json") +
                    " --max-influences 4",
                &output),
            0);
  EXPECT_NE(output.find("--max-influences requires --gltf"), std::string::npos) << output;
}

TEST_F(SkeletonCli, DefaultPrimitivesAreCylindersOnly) {
  std::string output;
  ASSERT_EQ(
      run("skeleton " + path("figure.off") + " --clusters 12 -q -o " + path("s.json"), &output), 0)
      << output;
  const json s = json::parse(testing::file_contents(path("s.json")));
  EXPECT_EQ(s["primitives"], "cylinder");
  EXPECT_EQ(s["bones"].size(), 12u);
}

TEST_F(SkeletonCli, AutomaticLevelIsTheOneSegmentChooses) {
  std::string output;
  ASSERT_EQ(run("segment " + path("figure.off") +
                    " --clusters auto --primitives cylinder,sphere -q --json " + path("seg.json"),
                &output),
            0)
      << output;
  const json segmented = json::parse(testing::file_contents(path("seg.json")));
  ASSERT_EQ(run("skeleton " + path("figure.off") +
                    " --clusters auto --primitives cylinder,sphere -q -o " + path("auto.json"),
                &output),
            0)
      << output;
  const json s = json::parse(testing::file_contents(path("auto.json")));
  EXPECT_EQ(s["requested_clusters"], "auto");
  EXPECT_EQ(s["cluster_count"], segmented["level"]["clusters"]);
  EXPECT_EQ(s["bones"].size(), s["cluster_count"].get<std::size_t>());
}

TEST_F(SkeletonCli, DeformRotatesTheForearmAndLeavesTheRestInPlace) {
  const json s = skeleton();
  const std::uint32_t elbow = nearest_joint(s, figure_.elbow[1]);
  {
    std::ofstream pose(path("pose.json"));
    pose << R"({"rotations": [{"joint": )" << elbow << R"(, "axis": [0, 1, 0], "degrees": 90}]})";
  }
  std::string output;
  ASSERT_EQ(run("deform " + path("figure.off") + " " + path("skeleton.json") + " " +
                    path("pose.json") + " -o " + path("posed.ply") + " --png " + path("posed.png"),
                &output),
            0)
      << output;
  EXPECT_EQ(testing::file_contents(path("posed.png")).substr(0, 4), "\x89PNG");
  const Mesh posed = read_mesh(path("posed.ply"));
  ASSERT_EQ(posed.vertex_count(), figure_.mesh.vertex_count());
  double moved = 0;
  for (std::uint32_t v = 0; v < posed.vertex_count(); ++v) {
    const Vec3& before = figure_.mesh.positions[v];
    // Away from the right arm's elbow, nothing moves at all.
    if (before[0] < 1.5) {
      ASSERT_EQ(posed.positions[v], before) << "vertex " << v;
    }
    moved = std::max(
        moved, std::hypot(posed.positions[v][0] - before[0], posed.positions[v][1] - before[1],
                          posed.positions[v][2] - before[2]));
  }
  EXPECT_GT(moved, 1.0);
}

TEST_F(SkeletonCli, BadInputGivesAClearError) {
  const json s = skeleton();
  std::uint32_t virtual_joint = 0;
  for (const json& joint : s["joints"])
    if (joint["kind"] == "virtual") virtual_joint = joint["id"];
  const auto deform_with = [&](const std::string& pose_text, std::string* output,
                               const std::string& mesh = "figure.off") {
    std::ofstream(path("pose.json")) << pose_text;
    return run("deform " + path(mesh) + " " + path("skeleton.json") + " " + path("pose.json") +
                   " -o " + path("out.off"),
               output);
  };
  std::string output;
  EXPECT_EQ(deform_with(R"({"rotations": [{"joint": )" + std::to_string(virtual_joint) +
                            R"(, "axis": [0, 0, 1], "degrees": 30}]})",
                        &output),
            1);
  std::string sensitive;  // the message names the joints that do rotate
  for (const json& joint : s["joints"])
    if (joint["kind"] == "sensitive")
      sensitive += (sensitive.empty() ? "" : ", ") + std::to_string(joint["id"].get<int>());
  ASSERT_FALSE(sensitive.empty());
  EXPECT_NE(output.find("only sensitive joints rotate (this skeleton's: " + sensitive),
            std::string::npos)
      << output;
  EXPECT_EQ(deform_with(R"({"rotations": [{"joint": 0, "axis": [0, 0], "degrees": 30}]})", &output),
            1);
  EXPECT_NE(output.find("axis must be an array of 3 numbers"), std::string::npos) << output;
  EXPECT_EQ(deform_with(R"({"rotations": [)", &output), 1);
  EXPECT_NE(output.find("not valid JSON"), std::string::npos) << output;

  // A skeleton made from another mesh.
  const Mesh other = testing::grid_mesh(3, 3, [](double u, double v) { return Vec3{u, v, 0}; });
  write_mesh(path("other.off"), other);
  EXPECT_EQ(deform_with(R"({"rotations": []})", &output, "other.off"), 1);
  EXPECT_NE(output.find("was made from a mesh of"), std::string::npos) << output;

  // A truncated skeleton file.
  const std::string text = testing::file_contents(path("skeleton.json"));
  std::ofstream(path("skeleton.json")) << text.substr(0, text.size() / 2);
  EXPECT_EQ(deform_with(R"({"rotations": []})", &output), 1);
  EXPECT_NE(output.find("not valid JSON"), std::string::npos) << output;

  // skeleton: a level is required; a bad band is refused.
  EXPECT_EQ(run("skeleton " + path("figure.off") + " -o " + path("x.json"), &output), 1);
  EXPECT_NE(output.find("--clusters"), std::string::npos) << output;
  EXPECT_EQ(run("skeleton " + path("figure.off") + " --clusters 8 --band -1 -o " + path("x.json"),
                &output),
            1);
  EXPECT_NE(output.find("--band"), std::string::npos) << output;
  EXPECT_EQ(
      run("skeleton " + path("figure.off") + " --clusters 8 --joints hubs -o " + path("x.json"),
          &output),
      1);
  EXPECT_NE(output.find("--joints: 'hubs' is not paper or limbs"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(path("x.json")));

  // skeleton and view check the rule and the band before reading the mesh (a large one takes a
  // while): a missing mesh is not what they report.
  for (const std::string command : {"skeleton", "view"})
    for (const std::string option : {"--joints hubs", "--band -1"}) {
      EXPECT_EQ(run(command + " " + path("missing.off") + " --clusters 8 " + option + " -o " +
                        path("x.out"),
                    &output),
                1)
          << command << " " << option;
      EXPECT_NE(output.find(option.substr(0, option.find(' ')) + ":"), std::string::npos)
          << command << ": " << output;
    }
}

}  // namespace
}  // namespace primseg
