#include "core/io/phantom.h"

#include <gtest/gtest.h>

#include "core/geometry/enclosed_volume.h"

namespace deform {
namespace {

TEST(KneePhantom, IsAValidClosedOutwardFacingLeg) {
  auto phantom = MakeKneePhantom();
  ASSERT_TRUE(phantom.ok());
  EXPECT_TRUE(ValidateMesh(phantom->mesh).ok());
  EXPECT_NEAR(phantom->mesh.num_vertices(), kDefaultPhantomVertices,
              0.05 * kDefaultPhantomVertices);
  // Closed: every edge has two triangles, so Euler characteristic 2 (a sphere).
  EXPECT_EQ(phantom->mesh.num_vertices() - phantom->mesh.num_triangles() / 2, 2);
  // Outward normals give a positive volume; a tapered cylinder of ~0.6 dm radius, 8.6 dm long.
  const double volume = EnclosedVolume(phantom->mesh.vertices, phantom->mesh.triangles);
  EXPECT_GT(volume, 5.0);
  EXPECT_LT(volume, 15.0);
  EXPECT_EQ(phantom->skeleton.InnerJoints(), std::vector<int>{1});
  EXPECT_EQ(phantom->skeleton.joint(1).name, "knee");
  EXPECT_EQ(phantom->skeleton.joint(1).dofs.size(), 3u);
}

TEST(KneePhantom, IsDeterministicAndScales) {
  auto a = MakeKneePhantom(5000), b = MakeKneePhantom(5000);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->mesh.vertices, b->mesh.vertices);
  EXPECT_EQ(a->mesh.triangles, b->mesh.triangles);
  auto large = MakeKneePhantom(120000);
  ASSERT_TRUE(large.ok());
  EXPECT_NEAR(large->mesh.num_vertices(), 120000, 0.05 * 120000);
  EXPECT_TRUE(ValidateMesh(large->mesh).ok());
}

TEST(KneePhantom, RefusesAbsurdResolutions) {
  EXPECT_EQ(MakeKneePhantom(10).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(MakeKneePhantom(kMaxPhantomVertices + 1).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace deform
