#include "core/eval/quality.h"

#include <gtest/gtest.h>

namespace deform {
namespace {

// A unit cube as 12 outward triangles.
TriangleMesh Cube() {
  TriangleMesh m;
  m.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i) m.vertices.row(i) << (i & 1), (i >> 1) & 1, (i >> 2) & 1;
  m.triangles.resize(12, 3);
  m.triangles << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2,
      4, 6, 1, 3, 5, 3, 7, 5;
  return m;
}

TEST(EnclosedVolume, OfAClosedCube) {
  const TriangleMesh cube = Cube();
  EXPECT_NEAR(EnclosedVolume(cube.vertices, cube.triangles), 1.0, 1e-12);
}

TEST(EnclosedVolume, ClosesOpenBoundariesWithAFan) {
  TriangleMesh open = Cube();
  open.triangles.conservativeResize(10, 3);  // drop the last face (x = 1): a square hole
  EXPECT_NEAR(EnclosedVolume(open.vertices, open.triangles), 1.0, 1e-12);
}

TEST(SkinClearance, RatioOfPosedToRestDistance) {
  std::vector<Joint> joints(2);
  joints[0].name = "a";
  joints[0].rest_position = {0, 0, 0};
  joints[1].name = "b";
  joints[1].rest_position = {0, 10, 0};
  auto skeleton = Skeleton::Create(joints, {{0, 1}});
  ASSERT_TRUE(skeleton.ok());
  Positions rest(4, 3), posed(4, 3);
  rest << 1, 1, 0, 2, 2, 0, 1, 3, 0, 1, 4, 0;
  posed << 0.25, 1, 0, 2, 2, 0, 1, 3, 0, 1, 4, 0;
  const std::vector<RigidTransform> bones(1);
  const ClearanceStats stats = SkinClearance(rest, posed, *skeleton, bones);
  EXPECT_DOUBLE_EQ(stats.min, 0.25);
  EXPECT_DOUBLE_EQ(stats.sink_fraction, 0.25);
}

}  // namespace
}  // namespace deform
