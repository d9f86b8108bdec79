#include "core/io/skeleton_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/geometry/skeleton.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

constexpr char kLegTgf[] =
    "1 1.103650 0.486150 0.122950\n"
    "2 1.581150 -3.694825 0.320250\n"
    "3 2.196200 -7.447850 -0.009100\n"
    "#\n"
    "1 2 1 0 0\n"
    "2 3 1 0 0\n"
    "#\n";

TEST(ParseTgf, ReadsJointsAndBones) {
  auto skeleton = ParseTgf(kLegTgf);
  ASSERT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  EXPECT_EQ(skeleton->num_joints(), 3);
  EXPECT_EQ(skeleton->num_bones(), 2);
  EXPECT_EQ(skeleton->joint(1).name, "joint1");
  EXPECT_DOUBLE_EQ(skeleton->joint(1).rest_position.y(), -3.694825);
  EXPECT_EQ(skeleton->bone(1).parent_bone, 0);
  EXPECT_EQ(skeleton->InnerJoints(), std::vector<int>{1});
}

TEST(ParseTgf, SkipsExtraColumnsAndOrdersBonesParentsFirst) {
  // Children listed before parents, extra columns after x y z (as arm.tgf has).
  auto skeleton = ParseTgf("1 0 0 0 9 9 9\n2 0 -1 0 9 9 9\n3 0 -2 0 9 9 9\n#\n2 3\n1 2\n#\n");
  ASSERT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  EXPECT_EQ(skeleton->bone(0).parent_bone, 1);
  EXPECT_EQ(skeleton->BonesParentsFirst(), (std::vector<int>{1, 0}));
}

TEST(ParseTgf, ReadsTheSharedSkeletons) {
  DEFORM_REQUIRE_SHARED_FILE(leg, "leg/leg.tgf");
  DEFORM_REQUIRE_SHARED_FILE(arm, "arm/arm.tgf");
  auto leg_skeleton = ReadSkeletonFile(leg);
  ASSERT_TRUE(leg_skeleton.ok()) << leg_skeleton.status().ToString();
  EXPECT_EQ(leg_skeleton->num_joints(), 5);
  EXPECT_EQ(leg_skeleton->InnerJoints(), (std::vector<int>{1, 2, 3}));
  auto arm_skeleton = ReadSkeletonFile(arm);
  ASSERT_TRUE(arm_skeleton.ok()) << arm_skeleton.status().ToString();
  EXPECT_EQ(arm_skeleton->num_bones(), 4);
}

TEST(ParseTgf, RefusesMalformedInput) {
  EXPECT_EQ(ParseTgf("").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(ParseTgf("1 0 0\n#\n#\n").status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(ParseTgf("1 0 0 0\n2 0 1 0\n#\n1 7\n#\n").status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(ParseTgf("1 nan 0 0\n2 0 1 0\n#\n1 2\n#\n").status().code(),
            StatusCode::kInvalidArgument);
  // Zero-length bone, a joint with two parents, a cycle.
  EXPECT_EQ(ParseTgf("1 0 0 0\n2 0 0 0\n#\n1 2\n#\n").status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(ParseTgf("1 0 0 0\n2 0 1 0\n3 1 0 0\n#\n1 3\n2 3\n#\n").status().code(),
            StatusCode::kInvalidArgument);
  auto cycle = ParseTgf("1 0 0 0\n2 0 1 0\n#\n1 2\n2 1\n#\n");
  ASSERT_FALSE(cycle.ok());
}

TEST(SkeletonJson, RoundTripsNamesAndDegreesOfFreedom) {
  const char* json = R"({
    "joints": [
      {"name": "hip", "position": [0, 8, 0]},
      {"name": "knee", "position": [0, 4, 0],
       "dofs": [{"name": "flexion", "axis": [2, 0, 0], "min": -5, "max": 150}]},
      {"name": "ankle", "position": [0, 0, 0]}],
    "bones": [["hip", "knee"], ["knee", 2]]})";
  auto skeleton = ParseSkeletonJson(json);
  ASSERT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  ASSERT_EQ(skeleton->joint(1).dofs.size(), 1u);
  EXPECT_DOUBLE_EQ(skeleton->joint(1).dofs[0].axis.x(), 1.0);  // normalized
  auto again = ParseSkeletonJson(SkeletonToJson(*skeleton));
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_EQ(again->joint(1).name, "knee");
  EXPECT_DOUBLE_EQ(again->joint(1).dofs[0].max_degrees, 150);
  EXPECT_EQ(*again->FindJoint("knee"), 1);
  EXPECT_EQ(*again->FindJoint("2"), 2);
  EXPECT_EQ(again->FindJoint("elbow").status().code(), StatusCode::kNotFound);
}

TEST(SkeletonJson, RefusesMalformedInput) {
  EXPECT_FALSE(ParseSkeletonJson("{").ok());
  EXPECT_FALSE(ParseSkeletonJson(R"({"joints": []})").ok());
  EXPECT_FALSE(
      ParseSkeletonJson(R"({"joints": [{"name": "a", "position": [0, 0]}], "bones": []})").ok());
  EXPECT_FALSE(ParseSkeletonJson(R"({"joints": [{"name": "a", "position": [0,0,0]},
      {"name": "a", "position": [0,1,0]}], "bones": [["a", "a"]]})")
                   .ok());
  auto bad_range = ParseSkeletonJson(R"({"joints": [{"name": "a", "position": [0,0,0],
      "dofs": [{"name": "f", "axis": [1,0,0], "min": 10, "max": -10}]},
      {"name": "b", "position": [0,1,0]}], "bones": [["a", "b"]]})");
  ASSERT_FALSE(bad_range.ok());
  EXPECT_NE(bad_range.status().message().find("range"), std::string::npos);
}

TEST(SkeletonJson, RefusesKeysOutsideTheFormatByName) {
  auto expect_refused = [](const char* json, const std::string& needle) {
    auto result = ParseSkeletonJson(json);
    ASSERT_FALSE(result.ok()) << json;
    EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(result.status().message().find(needle), std::string::npos)
        << result.status().message();
  };
  constexpr char kTwoJoints[] = R"("joints": [{"name": "a", "position": [0,0,0]},
      {"name": "b", "position": [0,1,0]}], "bones": [["a", "b"]])";
  expect_refused((std::string("{") + kTwoJoints + R"(, "weights": []})").c_str(),
                 "key 'weights', which is not part of the skeleton JSON format");
  expect_refused((std::string("{") + kTwoJoints + R"(, "root": "a"})").c_str(), "key 'root'");
  expect_refused(R"({"joints": [{"name": "a", "pos": [0,0,0], "position": [0,0,0]}],
      "bones": []})",
                 "joint 0 has key 'pos'");
  expect_refused(R"({"joints": [{"name": "a", "position": [0,0,0],
      "dofs": [{"name": "f", "axis": [1,0,0], "limit": 3}]}], "bones": []})",
                 "dof has key 'limit'");
  expect_refused(R"({"asset": {"version": "2.0"}, "nodes": []})", "glTF rig");
}

TEST(SkeletonFormat, IsToldByContentAndNamesForeignFormats) {
  EXPECT_EQ(*SkeletonFormatFromBytes(kLegTgf), SkeletonFormat::kTgf);
  EXPECT_EQ(*SkeletonFormatFromBytes("\xEF\xBB\xBF  {\"joints\": []}"), SkeletonFormat::kJson);
  constexpr char kBvh[] =
      "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xrotation Yrotation Zrotation\n}\n"
      "MOTION\nFrames: 0\n";
  for (const auto& status : {SkeletonFormatFromBytes(kBvh).status(),
                             ParseSkeletonJson(kBvh).status(), ParseTgf(kBvh).status()}) {
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(status.message(), kBvhNotSupported);
  }
  EXPECT_NE(
      SkeletonFormatFromBytes(std::string("glTF\x02\0\0\0", 8)).status().message().find("glTF rig"),
      std::string::npos);
  auto unknown = SkeletonFormatFromBytes("<skeleton/>");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("unknown skeleton format"), std::string::npos);
}

TEST(SkeletonFormat, ReadSkeletonFileNamesBvhWhateverTheExtension) {
  const auto dir = std::filesystem::temp_directory_path();
  for (const char* name : {"deform_bvh_test.bvh", "deform_bvh_test.json", "deform_bvh_test.tgf"}) {
    const std::string path = (dir / name).string();
    {
      std::ofstream out(path);
      out << "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n}\nMOTION\n";
    }
    auto skeleton = ReadSkeletonFile(path);
    std::filesystem::remove(path);
    ASSERT_FALSE(skeleton.ok()) << name;
    EXPECT_EQ(skeleton.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(skeleton.status().message().find(kBvhNotSupported), std::string::npos)
        << skeleton.status().message();
  }
  // A TGF under another name is told by its content.
  const std::string path = (dir / "deform_tgf_test.txt").string();
  {
    std::ofstream out(path);
    out << kLegTgf;
  }
  auto skeleton = ReadSkeletonFile(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  EXPECT_EQ(skeleton->num_joints(), 3);
}

}  // namespace
}  // namespace deform
