#include "core/base/pose_spec.h"

#include <gtest/gtest.h>

namespace deform {
namespace {

TEST(ParsePoseSpecTerms, SplitsTermsAndTrimsFields) {
  auto terms = ParsePoseSpecTerms(" knee : flexion : 90 ,0:x:-10.5");
  ASSERT_TRUE(terms.ok()) << terms.status().ToString();
  ASSERT_EQ(terms->size(), 2u);
  EXPECT_EQ((*terms)[0].joint, "knee");
  EXPECT_EQ((*terms)[0].axis, "flexion");
  EXPECT_EQ((*terms)[0].degrees, 90);
  EXPECT_EQ((*terms)[1].joint, "0");
  EXPECT_EQ((*terms)[1].axis, "x");
  EXPECT_EQ((*terms)[1].degrees, -10.5);
}

TEST(ParsePoseSpecTerms, ReadsTheAxisAndAngleFromTheRightAndQuotedNames) {
  auto terms = ParsePoseSpecTerms(
      "mixamorig:LeftForeArm:z:60, \"left arm, upper\" : x : -5,a:b:c:x:1, \"q:r\":y:2");
  ASSERT_TRUE(terms.ok()) << terms.status().ToString();
  ASSERT_EQ(terms->size(), 4u);
  EXPECT_EQ((*terms)[0].joint, "mixamorig:LeftForeArm");
  EXPECT_EQ((*terms)[0].axis, "z");
  EXPECT_EQ((*terms)[0].degrees, 60);
  EXPECT_EQ((*terms)[1].joint, "left arm, upper");
  EXPECT_EQ((*terms)[1].axis, "x");
  EXPECT_EQ((*terms)[1].degrees, -5);
  EXPECT_EQ((*terms)[2].joint, "a:b:c");
  EXPECT_EQ((*terms)[3].joint, "q:r");
  EXPECT_EQ((*terms)[3].axis, "y");
  auto unclosed = ParsePoseSpecTerms("\"left arm:x:10");
  ASSERT_FALSE(unclosed.ok());
  EXPECT_NE(unclosed.status().message().find("unclosed"), std::string::npos)
      << unclosed.status().message();
}

TEST(ParsePoseSpecTerms, RestAndEmptyAreNoTerm) {
  for (const char* rest : {"", "rest", "  rest "}) {
    auto terms = ParsePoseSpecTerms(rest);
    ASSERT_TRUE(terms.ok()) << rest;
    EXPECT_TRUE(terms->empty()) << rest;
  }
}

TEST(ParsePoseSpecTerms, RefusesMalformedTermsNamingThem) {
  for (const char* bad :
       {"knee:flexion", ":x:10", "\"a\"x:10", "\"a\":b:x:10", "knee::10", "knee:x:", "knee:x:abc",
        "knee:x:nan", "knee:x:inf", "knee:x:10,,", "knee:x:10,"}) {
    auto terms = ParsePoseSpecTerms(bad);
    ASSERT_FALSE(terms.ok()) << bad;
    EXPECT_EQ(terms.status().code(), StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(terms.status().message().find("pose term '"), std::string::npos)
        << terms.status().message();
  }
  EXPECT_EQ(ParsePoseSpecTerms("knee:x:abc").status().message(),
            "pose term 'knee:x:abc': 'abc' is not a finite number of degrees");
  EXPECT_EQ(ParsePoseSpecTerms("a:x:1, knee:flexion").status().message(),
            "pose term 'knee:flexion' is not JOINT:AXIS:DEGREES");
}

}  // namespace
}  // namespace deform
