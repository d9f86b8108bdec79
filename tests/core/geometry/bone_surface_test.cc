#include "core/geometry/bone_surface.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/geometry/enclosed_volume.h"
#include "core/geometry/primitive_surfaces.h"
#include "core/geometry/triangle_bvh.h"
#include "core/io/phantom.h"

namespace deform {
namespace {

TEST(PrimitiveSurfaces, CapsuleIsClosedOutwardAndAtItsRadius) {
  const Eigen::Vector3d a(0, 0, 0), b(0, 2, 0);
  const double radius = 0.5;
  const TriangleMesh capsule = MakeCapsule(a, b, radius, 24, 8);
  ASSERT_TRUE(ValidateMesh(capsule).ok());
  for (int i = 0; i < capsule.num_vertices(); ++i) {
    const Eigen::Vector3d p = capsule.vertices.row(i).transpose();
    const double t = std::clamp(p.y(), 0.0, 2.0);
    EXPECT_NEAR((p - Eigen::Vector3d(0, t, 0)).norm(), radius, 1e-12) << i;
  }
  // Outward: a positive volume, a little below the exact one (the polygon is inscribed).
  const double exact = M_PI * radius * radius * 2 + 4.0 / 3 * M_PI * std::pow(radius, 3);
  const double volume = EnclosedVolume(capsule.vertices, capsule.triangles);
  EXPECT_GT(volume, 0.95 * exact);
  EXPECT_LT(volume, exact);
  const Skeleton skeleton = *Skeleton::Create({{"a", a, {}}, {"b", b, {}}}, {{0, 1}});
  EXPECT_TRUE(ValidateBoneSurfaces({{"capsule", 0, -1, 0, capsule}}, skeleton).ok());
}

TEST(PrimitiveSurfaces, SphereAndEllipsoidAreClosed) {
  const TriangleMesh sphere = MakeCapsule(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 1);
  EXPECT_TRUE(ValidateMesh(sphere).ok());
  EXPECT_GT(EnclosedVolume(sphere.vertices, sphere.triangles), 0);
  const TriangleMesh ellipsoid =
      MakeEllipsoid(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 2, 0.5).asDiagonal());
  EXPECT_TRUE(ValidateMesh(ellipsoid).ok());
  EXPECT_NEAR(EnclosedVolume(ellipsoid.vertices, ellipsoid.triangles), 4.0 / 3 * M_PI, 0.4);
}

TEST(BoneSurfaces, ValidationNamesTheProblem) {
  const KneePhantom phantom = *MakeKneePhantom(600);
  std::vector<BoneSurface> surfaces = phantom.bones;
  ASSERT_EQ(surfaces.size(), 3u);
  EXPECT_TRUE(ValidateBoneSurfaces(surfaces, phantom.skeleton).ok());

  std::vector<BoneSurface> bad = surfaces;
  bad[0].bone = 7;
  EXPECT_NE(ValidateBoneSurfaces(bad, phantom.skeleton).message().find("out of range"),
            std::string::npos);
  bad = surfaces;
  bad[0].blend_bone = 0;  // not a child of bone 0
  EXPECT_FALSE(ValidateBoneSurfaces(bad, phantom.skeleton).ok());
  bad = surfaces;
  bad[1].mesh.triangles.conservativeResize(bad[1].mesh.num_triangles() - 1, 3);
  const Status open = ValidateBoneSurfaces(bad, phantom.skeleton);
  EXPECT_NE(open.message().find("is not closed"), std::string::npos) << open.ToString();
  EXPECT_NE(open.message().find("tibia"), std::string::npos) << open.ToString();
  BoneSurfaceLimits limits;
  limits.max_surfaces = 2;
  EXPECT_EQ(ValidateBoneSurfaces(surfaces, phantom.skeleton, {}, limits).code(),
            StatusCode::kResourceExhausted);
}

TEST(BoneSurfaces, CapsulesByTheSizingRuleLieInsideTheSkin) {
  const KneePhantom phantom = *MakeKneePhantom(2000);
  const std::vector<BoneSurface> capsules = MakeCapsuleBoneSurfaces(phantom.mesh, phantom.skeleton);
  ASSERT_EQ(capsules.size(), 2u);
  EXPECT_EQ(capsules[0].name, "hip-knee");
  for (const BoneSurface& capsule : capsules) {
    const TriangleBvh bvh(capsule.mesh);
    for (int i = 0; i < phantom.mesh.num_vertices(); ++i) {
      ASSERT_FALSE(bvh.Contains(phantom.mesh.vertices.row(i).transpose())) << i;
    }
    // Inside the skin: the capsule's points are all inside the closed leg.
    const TriangleBvh skin(phantom.mesh);
    for (int i = 0; i < capsule.mesh.num_vertices(); i += 7) {
      ASSERT_TRUE(skin.Contains(capsule.mesh.vertices.row(i).transpose())) << capsule.name << i;
    }
  }
}

TEST(BoneSurfaces, ThePatellaTurnsByHalfTheKnee) {
  const KneePhantom phantom = *MakeKneePhantom(600);
  const BoneSurface& patella = phantom.bones[2];
  ASSERT_EQ(patella.name, "patella");
  std::vector<RigidTransform> bones(2);
  bones[1].rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX());
  const Eigen::Vector3d knee = phantom.skeleton.joint(1).rest_position;
  bones[1].translation = knee - bones[1].rotation * knee;
  const RigidTransform pose = BoneSurfaceTransform(patella, phantom.skeleton, bones);
  EXPECT_NEAR(Eigen::AngleAxisd(pose.rotation).angle(), M_PI / 4, 1e-12);
  EXPECT_NEAR((pose.Apply(knee) - knee).norm(), 0, 1e-12);
}

TEST(TriangleBvh, ClosestPointOnASphere) {
  const TriangleMesh sphere =
      MakeCapsule(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 1, 32, 16);
  const TriangleBvh bvh(sphere);
  const TriangleBvh::SurfacePoint inside = bvh.ClosestPoint(Eigen::Vector3d(0.2, 0.1, 0));
  EXPECT_NEAR(inside.point.norm(), 1, 0.01);
  EXPECT_NEAR(inside.distance, 1 - std::sqrt(0.05), 0.01);
  EXPECT_GE(inside.triangle, 0);
  EXPECT_GT(bvh.TriangleNormal(inside.triangle).dot(inside.point), 0.9);
  EXPECT_DOUBLE_EQ(bvh.DistanceToSurface(Eigen::Vector3d(0.2, 0.1, 0)), inside.distance);
}

}  // namespace
}  // namespace deform
