#include "igtl/joint_angle_input.h"

#include <gtest/gtest.h>

namespace deform::igtl_bridge {
namespace {

deform::v1::MeshSummary Knee() {
  deform::v1::MeshSummary summary;
  summary.add_joints()->set_name("hip");
  deform::v1::JointInfo* knee = summary.add_joints();
  knee->set_name("knee");
  knee->add_dofs()->set_name("flexion");
  return summary;
}

std::string Text(const deform::v1::PoseUpdate& pose) {
  std::string text;
  for (const deform::v1::JointAngle& angle : pose.angles()) {
    text += angle.joint() + ":" + angle.axis() + ":" + std::to_string(angle.degrees()) + ";";
  }
  return text;
}

TEST(JointAngleInputTest, MessagesSetTheAnglesTheyNameAndKeepTheOthers) {
  JointAngleInput input(Knee());
  std::string error;
  EXPECT_EQ(Text(input.Pose()), "");
  ASSERT_TRUE(input.Apply("knee:flexion:90", &error)) << error;
  ASSERT_TRUE(input.Apply("0:x:10", &error)) << error;  // an index names the joint
  EXPECT_EQ(Text(input.Pose()), "knee:flexion:90.000000;hip:x:10.000000;");
  ASSERT_TRUE(input.Apply(" 1:flexion:45 ", &error)) << error;
  EXPECT_EQ(Text(input.Pose()), "knee:flexion:45.000000;hip:x:10.000000;");
  ASSERT_TRUE(input.Apply("rest", &error)) << error;
  EXPECT_EQ(Text(input.Pose()), "");
}

TEST(JointAngleInputTest, MalformedOrUnknownTermsChangeNothing) {
  JointAngleInput input(Knee());
  std::string error;
  ASSERT_TRUE(input.Apply("knee:flexion:30", &error)) << error;
  for (const char* bad : {"knee:flexion", "knee=90", "", "ankle:x:5", "2:x:5", "hip:flexion:5",
                          "knee:flexion:abc", "knee:flexion:10,ankle:x:5"}) {
    error.clear();
    EXPECT_FALSE(input.Apply(bad, &error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
  EXPECT_EQ(Text(input.Pose()), "knee:flexion:30.000000;");
}

}  // namespace
}  // namespace deform::igtl_bridge
