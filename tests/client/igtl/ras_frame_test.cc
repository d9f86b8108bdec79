#include "igtl/ras_frame.h"

#include <gtest/gtest.h>

#include <cmath>

namespace deform::igtl_bridge {
namespace {

TEST(RasFrameTest, IdentityByDefault) {
  const RasFrame frame;
  const float in[3] = {1.5f, -2, 3};
  float out[3];
  frame.MapPoint(in, out);
  EXPECT_FLOAT_EQ(out[0], 1.5f);
  EXPECT_FLOAT_EQ(out[1], -2);
  EXPECT_FLOAT_EQ(out[2], 3);
  EXPECT_FALSE(frame.mirrors());
}

TEST(RasFrameTest, YUpFacingZBecomesRasMillimetres) {
  RasFrame frame;
  std::string error;
  ASSERT_TRUE(RasFrame::Parse("-x,z,y", 100, &frame, &error)) << error;
  EXPECT_FALSE(frame.mirrors());  // a rotation: -1 times an odd permutation
  const float in[3] = {1, 2, 3};
  float out[3];
  frame.MapPoint(in, out);
  EXPECT_FLOAT_EQ(out[0], -100);
  EXPECT_FLOAT_EQ(out[1], 300);
  EXPECT_FLOAT_EQ(out[2], 200);
}

// The mapped motion applied to a mapped rest point equals the mapped posed point.
TEST(RasFrameTest, MotionMapsConsistentlyWithPoints) {
  RasFrame frame;
  std::string error;
  ASSERT_TRUE(RasFrame::Parse("-x,z,y", 100, &frame, &error)) << error;
  const double c = std::cos(0.7), s = std::sin(0.7);
  // A rotation about model x, then a translation.
  const float rotation[9] = {1,
                             0,
                             0,
                             0,
                             static_cast<float>(c),
                             static_cast<float>(-s),
                             0,
                             static_cast<float>(s),
                             static_cast<float>(c)};
  const float translation[3] = {0.25f, -1, 2};
  const float rest[3] = {0.5f, 1.5f, -0.75f};
  float posed[3];
  for (int r = 0; r < 3; ++r) {
    posed[r] = rotation[3 * r] * rest[0] + rotation[3 * r + 1] * rest[1] +
               rotation[3 * r + 2] * rest[2] + translation[r];
  }
  float rest_ras[3], posed_ras[3];
  frame.MapPoint(rest, rest_ras);
  frame.MapPoint(posed, posed_ras);
  const auto m = frame.MapMotion(rotation, translation);
  for (std::size_t r = 0; r < 3; ++r) {
    const float moved =
        m[r][0] * rest_ras[0] + m[r][1] * rest_ras[1] + m[r][2] * rest_ras[2] + m[r][3];
    EXPECT_NEAR(moved, posed_ras[r], 1e-4) << r;
  }
  EXPECT_EQ(m[3][0], 0);
  EXPECT_EQ(m[3][3], 1);
}

TEST(RasFrameTest, ReflectionsAreFlaggedAndBadSpecsRefused) {
  RasFrame frame;
  std::string error;
  ASSERT_TRUE(RasFrame::Parse("-x,y,z", 1, &frame, &error));
  EXPECT_TRUE(frame.mirrors());
  ASSERT_TRUE(RasFrame::Parse("y,x,z", 1, &frame, &error));
  EXPECT_TRUE(frame.mirrors());
  ASSERT_TRUE(RasFrame::Parse("+y,-x,z", 1, &frame, &error));
  EXPECT_FALSE(frame.mirrors());
  for (const char* bad : {"x,x,y", "x,y", "x,y,z,x", "x,y,w", "", "--x,y,z"}) {
    EXPECT_FALSE(RasFrame::Parse(bad, 1, &frame, &error)) << bad;
  }
  EXPECT_FALSE(RasFrame::Parse("x,y,z", 0, &frame, &error));
  EXPECT_FALSE(RasFrame::Parse("x,y,z", NAN, &frame, &error));
}

}  // namespace
}  // namespace deform::igtl_bridge
