// The skeleton and pose files (skeleton_io.hpp): a skeleton reads back bit for bit, what the
// reader refuses it refuses with the file's name and the reason, and poses read as deform reads
// them.

#include "primseg/skeleton_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>

#include "primseg/cut.hpp"
#include "primseg/error.hpp"
#include "primseg/hierarchy.hpp"
#include "support/stick_figure.hpp"
#include "support/test_support.hpp"

namespace primseg {
namespace {

using nlohmann::json;

// The stick figure's skeleton at its 8 parts (cylinders and spheres).
const Skeleton& stick_figure_skeleton() {
  static const Skeleton skeleton = [] {
    HierarchyOptions options;
    options.primitives = {PrimitiveType::Cylinder, PrimitiveType::Sphere};
    const Hierarchy hierarchy = build_hierarchy(testing::make_stick_figure().mesh, options);
    return extract_skeleton(hierarchy, cut_by_count(hierarchy, 8));
  }();
  return skeleton;
}

void expect_same(const Skeleton& a, const Skeleton& b) {
  EXPECT_EQ(a.face_labels, b.face_labels);
  ASSERT_EQ(a.joints.size(), b.joints.size());
  for (std::size_t j = 0; j < a.joints.size(); ++j) {
    EXPECT_EQ(a.joints[j].id, b.joints[j].id);
    EXPECT_EQ(a.joints[j].position, b.joints[j].position);  // bit for bit
    EXPECT_EQ(a.joints[j].kind, b.joints[j].kind);
    EXPECT_EQ(a.joints[j].visible, b.joints[j].visible);
    EXPECT_EQ(a.joints[j].bones, b.joints[j].bones);
  }
  ASSERT_EQ(a.bones.size(), b.bones.size());
  for (std::size_t i = 0; i < a.bones.size(); ++i) {
    EXPECT_EQ(a.bones[i].cluster, b.bones[i].cluster);
    EXPECT_EQ(a.bones[i].joints, b.bones[i].joints);
    EXPECT_EQ(a.bones[i].visible, b.bones[i].visible);
    EXPECT_EQ(a.bones[i].axis, b.bones[i].axis);
    EXPECT_EQ(a.bones[i].point, b.bones[i].point);
    EXPECT_EQ(a.bones[i].radius, b.bones[i].radius);
    EXPECT_EQ(a.bones[i].area, b.bones[i].area);
  }
}

TEST(SkeletonIo, ASkeletonReadsBackBitForBit) {
  const Skeleton& skeleton = stick_figure_skeleton();
  const std::string text = skeleton_json(skeleton);
  expect_same(parse_skeleton_json(text), skeleton);
  const json document = json::parse(text);
  EXPECT_EQ(document["cluster_count"], 8);
  EXPECT_EQ(document["root_bone"], 0);
  EXPECT_EQ(document["face_labels"].size(), skeleton.face_labels.size());

  const auto dir = testing::temp_directory("skeleton-io");
  write_skeleton(dir / "s.json", skeleton);
  expect_same(read_skeleton(dir / "s.json"), skeleton);
  std::filesystem::remove_all(dir);
}

TEST(SkeletonIo, MembersItDoesNotUseAreIgnored) {
  json document = json::parse(skeleton_json(stick_figure_skeleton()));
  document["mesh"] = {{"faces", 1234}};
  document["timing"] = {{"hierarchy_seconds", 0.5}};
  document["bones"][0]["note"] = "ignored";
  expect_same(parse_skeleton_json(document.dump()), stick_figure_skeleton());
}

// Each edit of a good file, and the words the refusal must contain.
TEST(SkeletonIo, MalformedFilesAreRefusedWithTheReason) {
  const json good = json::parse(skeleton_json(stick_figure_skeleton()));
  const auto refused = [](const std::string& text, const std::string& reason) {
    try {
      (void)parse_skeleton_json(text, "s.json");
      ADD_FAILURE() << "accepted; expected: " << reason;
    } catch (const ParseError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("'s.json'"), std::string::npos) << message;
      EXPECT_NE(message.find(reason), std::string::npos) << message;
    }
  };
  const auto edited = [&good](const std::function<void(json&)>& edit) {
    json copy = good;
    edit(copy);
    return copy.dump();
  };
  refused(good.dump().substr(0, 100), "not valid JSON");
  refused("[]", "missing \"bones\"");
  refused(edited([](json& s) { s.erase("joints"); }), "missing \"joints\"");
  refused(edited([](json& s) { s["bones"] = json::array(); }), "non-empty array");
  refused(edited([](json& s) { s["bones"][1]["id"] = 2; }), "ids must be 0..K-1 in order");
  refused(edited([](json& s) { s["joints"][0]["kind"] = "elastic"; }), "unknown kind");
  refused(edited([](json& s) { s["joints"][0]["position"] = {0, 1}; }), "array of 3 numbers");
  refused(edited([](json& s) { s["bones"][0]["axis"][2] = "x"; }), "array of 3 numbers");
  refused(edited([](json& s) { s["bones"][0]["radius"] = -1; }), "radius must be finite");
  refused(edited([](json& s) { s["bones"][0]["area"] = -0.5; }), "area must be finite");
  // A number beyond the doubles is no JSON number nlohmann reads (never an infinite area).
  std::string huge_area = good.dump();
  huge_area.replace(huge_area.find("\"area\":") + 7, 1, "1e999,\"was\":");
  refused(huge_area, "number overflow");
  refused(edited([](json& s) { s["face_labels"][0] = 8; }), "face label must be an integer in");
  refused(edited([](json& s) { s["root_bone"] = 1; }), "root_bone must be 0");
  // One side of a joint-bone link dropped: the first entry of the first non-empty `list` of the
  // `items`. Without a bone's joint, the joint lists a bone that does not list it back; without a
  // joint's bone, the bone lists a joint that does not ("bone B lists joint J, ...").
  const auto unlinked = [&](const char* items, const char* list) {
    return edited([&](json& s) {
      for (json& item : s[items]) {
        json& links = item[list];
        if (!links.empty()) {
          links.erase(links.begin());
          return;
        }
      }
    });
  };
  refused(unlinked("bones", "joints"), "which does not list it");
  refused(unlinked("joints", "bones"), "lists joint");
}

TEST(SkeletonIo, PosesReadInRadiansAndRefuseWhatIsNotAPose) {
  const std::vector<JointRotation> pose = parse_pose_json(
      R"({"rotations": [{"joint": 3, "axis": [0, 1, 0], "degrees": 90},
                        {"joint": 0, "axis": [1, 2, 3], "degrees": -45.5}]})");
  ASSERT_EQ(pose.size(), 2u);
  EXPECT_EQ(pose[0].joint, 3u);
  EXPECT_EQ(pose[0].axis, (Vec3{0, 1, 0}));
  EXPECT_DOUBLE_EQ(pose[0].angle, std::numbers::pi / 2);
  EXPECT_DOUBLE_EQ(pose[1].angle, -45.5 * std::numbers::pi / 180);
  EXPECT_TRUE(parse_pose_json(R"({"rotations": []})").empty());
  for (const auto& [text, reason] : std::vector<std::pair<std::string, std::string>>{
           {R"({"rotations": [)", "not valid JSON"},
           {R"({"pose": []})", "missing \"rotations\""},
           {R"({"rotations": [{"joint": -1, "axis": [0, 0, 1], "degrees": 1}]})", "joint"},
           {R"({"rotations": [{"joint": 0, "axis": [0, 0], "degrees": 1}]})", "array of 3"},
           {R"({"rotations": [{"joint": 0, "axis": [0, 0, 1], "degrees": "x"}]})", "degrees"}}) {
    try {
      (void)parse_pose_json(text, "pose.json");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const ParseError& e) {
      EXPECT_NE(std::string(e.what()).find("'pose.json'"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace primseg
