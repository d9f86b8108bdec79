// The skin a bone reaches across a joint (bone_reach.h): found over the joint's range of motion,
// left out of the rigid zones, so that contacts at a deep flexion move no anchored vertex.
#include "core/constraints/bone_reach.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/constraints/bone_contacts.h"
#include "core/constraints/skin_constraints.h"
#include "core/eval/quality.h"
#include "core/eval/skinning.h"
#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"
#include "core/model/rigid_cores.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

TEST(BoneReach, FindsTheSkinABoneAcrossTheJointSweepsAndNothingFarOff) {
  const KneePhantom phantom = *MakeKneePhantom(2000);
  const std::vector<int> reached =
      *SkinReachedAcrossJoints(phantom.mesh, phantom.skeleton, phantom.bones);
  ASSERT_FALSE(reached.empty());
  EXPECT_TRUE(std::is_sorted(reached.begin(), reached.end()));
  // The knee flexes to 150 degrees about +x, swinging the shin behind the thigh (its degree of
  // freedom's range; it extends by 5 only, and its other two turn by 30 at most): the reached skin
  // is the back of the knee, the thigh's and the calf's sides of the fold, and nothing else.
  const Eigen::Vector3d knee = phantom.skeleton.joint(1).rest_position;
  const double limb =
      phantom.skeleton.joint(0).rest_position.y() - phantom.skeleton.joint(2).rest_position.y();
  for (const int v : reached) {
    const Eigen::Vector3d x = phantom.mesh.vertices.row(v).transpose();
    EXPECT_LT(x.z(), knee.z()) << "vertex " << v << " in front of the knee";
    EXPECT_LT(std::abs(x.y() - knee.y()), 0.2 * limb) << "vertex " << v << " far from the knee";
  }
  int back_of_knee = 0;
  for (int v = 0; v < phantom.mesh.num_vertices(); ++v) {
    const Eigen::Vector3d x = phantom.mesh.vertices.row(v).transpose();
    if (x.z() < knee.z() && std::abs(x.y() - knee.y()) < 0.1 * limb) ++back_of_knee;
  }
  EXPECT_GT(static_cast<int>(reached.size()), back_of_knee / 10);
  // No surfaces, nothing reached; a limb without bones keeps its options.
  EXPECT_TRUE(SkinReachedAcrossJoints(phantom.mesh, phantom.skeleton, {})->empty());
  ModelOptions options;
  ASSERT_TRUE(
      UnanchorReachedSkin(phantom.mesh, phantom.skeleton, {}, ConstraintOptions{}, &options).ok());
  EXPECT_TRUE(options.unanchored_vertices.empty());
  ConstraintOptions off;
  off.bone_reach = false;
  ASSERT_TRUE(
      UnanchorReachedSkin(phantom.mesh, phantom.skeleton, phantom.bones, off, &options).ok());
  EXPECT_TRUE(options.unanchored_vertices.empty());
  off.bone_reach = true;
  off.max_contacts = 0;
  ASSERT_TRUE(
      UnanchorReachedSkin(phantom.mesh, phantom.skeleton, phantom.bones, off, &options).ok());
  EXPECT_TRUE(options.unanchored_vertices.empty());
  ASSERT_TRUE(UnanchorReachedSkin(phantom.mesh, phantom.skeleton, phantom.bones,
                                  ConstraintOptions{}, &options)
                  .ok());
  EXPECT_EQ(options.unanchored_vertices, reached);
}

TEST(BoneReach, IsCancellable) {
  const KneePhantom phantom = *MakeKneePhantom(800);
  CancelToken cancel;
  cancel.Cancel();
  const auto reached =
      SkinReachedAcrossJoints(phantom.mesh, phantom.skeleton, phantom.bones, {}, &cancel);
  EXPECT_EQ(reached.status().code(), StatusCode::kFailedPrecondition);
}

TEST(ReleaseFromRigidZones, KeepsAQuarterOfEachZoneTheFarthestFromTheJoints) {
  // Bone 0's zone: vertices 0..7 (relative distance = index); bone 1's: 8, 9; vertex 10 free.
  std::vector<int> rigid = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, -1};
  std::vector<double> distance = {0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 0};
  const auto released = ReleaseFromRigidZones({7, 6, 5, 4, 3, 2, 1, 0, 8, 10, 8}, distance,
                                              ModelOptions::kMinAnchoredFraction, &rigid);
  ASSERT_TRUE(released.ok());
  // Bone 0 keeps 2 of 8 (the farthest, 6 and 7); bone 1 keeps 1 of 2 (9); 10 was not rigid.
  EXPECT_EQ(*released, 7);
  EXPECT_EQ(rigid, (std::vector<int>{-1, -1, -1, -1, -1, -1, 0, 0, -1, 1, -1}));
  EXPECT_EQ(ReleaseFromRigidZones({11}, distance, 0.25, &rigid).status().code(),
            StatusCode::kInvalidArgument);
}

// The shared leg and arm with capsule bones: with the reached skin unanchored, a deep flexion's
// contacts leave every rigid zone on its bone (within 1e-4 of the diagonal of LBS, the method's
// rigid-zone bound), where the anchored skin of the other side was pushed before.
struct SharedCase {
  const char* mesh;
  const char* skeleton;
  const char* pose;
};

class SharedMeshReach : public ::testing::TestWithParam<SharedCase> {};

TEST_P(SharedMeshReach, DeepFlexionContactsLeaveTheRigidZonesOnTheirBones) {
  const SharedCase& c = GetParam();
  DEFORM_REQUIRE_SHARED_FILE(mesh_path, c.mesh);
  DEFORM_REQUIRE_SHARED_FILE(skeleton_path, c.skeleton);
  const TriangleMesh mesh = *ReadMeshFile(mesh_path);
  const Skeleton skeleton = *ReadSkeletonFile(skeleton_path);
  const std::vector<BoneSurface> surfaces = MakeCapsuleBoneSurfaces(mesh, skeleton);
  Pose pose;
  ASSERT_TRUE(PoseFromTerms(skeleton, *ParsePoseSpec(c.pose, skeleton), &pose).ok());
  std::vector<RigidTransform> transforms;
  ForwardKinematics(skeleton, pose, &transforms);
  double errors[2];
  for (const bool reach : {false, true}) {
    ModelOptions options = ModelOptions::Paper();
    if (reach) {
      ASSERT_TRUE(
          UnanchorReachedSkin(mesh, skeleton, surfaces, ConstraintOptions{}, &options).ok());
    }
    const auto model = *DeformationModel::Build(mesh, skeleton, options);
    const auto bones = *BoneContacts::Create(surfaces, skeleton, mesh, model->rigid_bones());
    const auto constraints = *SkinConstraints::Create(*model, bones);
    DeformScratch scratch = model->MakeScratch();
    ASSERT_TRUE(model->Deform(*model->default_factorization(), pose, &scratch));
    ConstraintScratch constraint_scratch = constraints->MakeScratch();
    ConstraintReport report;
    ASSERT_TRUE(constraints->Apply(*model->default_factorization(), &scratch, &constraint_scratch,
                                   &report));
    ASSERT_GT(report.contacts, 0);
    EXPECT_EQ(report.after.vertices, 0);
    Positions skinned;
    LinearBlendSkinning(mesh.vertices, model->bone_weights(), transforms, &skinned);
    const QualityReport quality = MeasureQuality(mesh, scratch.positions(), skeleton, transforms,
                                                 skinned, model->rigid_bones(), bones.get());
    errors[reach ? 1 : 0] = quality.rigid_zone_error;
  }
  EXPECT_GT(errors[0], 1e-3) << "without the reach, contacts push anchored skin";
  EXPECT_LE(errors[1], 1e-4);
}

INSTANTIATE_TEST_SUITE_P(Shared, SharedMeshReach,
                         ::testing::Values(SharedCase{"leg/leg_1633.obj", "leg/leg.tgf", "1:x:120"},
                                           SharedCase{"arm/arm_8311.obj", "arm/arm.tgf",
                                                      "2:z:-120"}));

}  // namespace
}  // namespace deform
