#include "core/model/body_binding.h"

#include <gtest/gtest.h>

#include "core/io/phantom.h"
#include "tests/core/model/rig_fixtures.h"

namespace deform {
namespace {

int BonesOfLegA(const Skeleton& skeleton) { return skeleton.num_bones() / 2; }

TEST(BodyBinding, KeepsEachLegOnItsOwnBonesWhereStraightLineCrossesToTheOther) {
  const test_support::Rig rig = test_support::TwoLegsSideBySide();
  const VertexAdjacency adjacency =
      BuildVertexAdjacency(rig.mesh.triangles, rig.mesh.num_vertices());
  const TriangleBvh bvh(rig.mesh);
  const BodyBinding binding = BindThroughBody(rig.mesh, rig.skeleton, adjacency, bvh);
  const std::vector<NearestBone> straight = NearestBones(rig.mesh.vertices, rig.skeleton);

  const int bones_a = BonesOfLegA(rig.skeleton);
  int straight_wrong = 0;
  int bound_wrong = 0;
  for (int i = 0; i < rig.mesh.num_vertices(); ++i) {
    const bool in_a = i < rig.first_leg_vertices;
    straight_wrong += (straight[i].bone < bones_a) != in_a;
    bound_wrong += (binding.bones[i].bone < bones_a) != in_a;
  }
  // The fixture is one where the straight line is wrong: part of leg A follows leg B's bones.
  EXPECT_GT(straight_wrong, 20) << "the fixture no longer tests anything";
  RecordProperty("straight_line_wrong", straight_wrong);
  EXPECT_EQ(bound_wrong, 0);
  EXPECT_GT(binding.reached_along_surface, 0);
  EXPECT_EQ(binding.straight_line, 0);
}

TEST(BodyBinding, AgreesWithTheNearestBoneOnASingleLimb) {
  auto phantom = MakeKneePhantom(2000);
  ASSERT_TRUE(phantom.ok());
  const VertexAdjacency adjacency =
      BuildVertexAdjacency(phantom->mesh.triangles, phantom->mesh.num_vertices());
  const TriangleBvh bvh(phantom->mesh);
  const BodyBinding binding = BindThroughBody(phantom->mesh, phantom->skeleton, adjacency, bvh);
  const std::vector<NearestBone> straight = NearestBones(phantom->mesh.vertices, phantom->skeleton);
  for (int i = 0; i < phantom->mesh.num_vertices(); ++i) {
    EXPECT_EQ(binding.bones[i].bone, straight[i].bone) << "vertex " << i;
    EXPECT_NEAR(binding.bones[i].distance, straight[i].distance, 1e-12);
  }
}

}  // namespace
}  // namespace deform
