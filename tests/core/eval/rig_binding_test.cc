// The method on rigs where binding by straight-line distance is wrong (issue: real rigs), and with
// a rig's own weights: rigid zones follow linear blend skinning with the same binding to 1e-3 of
// the diagonal, and bending one joint moves only what hangs from that joint.
#include <gtest/gtest.h>

#include <memory>

#include "core/eval/skinning.h"
#include "core/geometry/skin_weights.h"
#include "core/io/mesh_io.h"
#include "core/io/skeleton_io.h"
#include "core/model/deformation_model.h"
#include "tests/core/model/model_test_util.h"
#include "tests/core/model/rig_fixtures.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

using test_support::PoseFromSpec;

struct Frame {
  Positions posed;
  Positions lbs;
  std::vector<RigidTransform> bones;
};

Frame Deform(const DeformationModel& model, const Pose& pose) {
  Frame frame;
  DeformScratch scratch = model.MakeScratch();
  model.Deform(*model.default_factorization(), pose, &scratch);
  frame.posed =
      Eigen::Map<const Positions>(scratch.solution.data(), model.mesh().num_vertices(), 3);
  ForwardKinematics(model.skeleton(), pose, &frame.bones);
  LinearBlendSkinning(model.mesh().vertices, model.bone_weights(), frame.bones, &frame.lbs);
  return frame;
}

// The largest distance, over rigid-zone vertices, from linear blend skinning (relative to the
// diagonal).
double RigidZoneError(const DeformationModel& model, const Frame& frame) {
  double worst = 0;
  for (int i = 0; i < model.mesh().num_vertices(); ++i) {
    if (model.rigid_bones()[i] < 0) continue;
    worst = std::max(worst, (frame.posed.row(i) - frame.lbs.row(i)).norm());
  }
  return worst / model.bounding_box_diagonal();
}

// The joint's own bones (those that start or end at it) and the descendants of those that start
// at it: the bones whose vertices may move when `joint` turns.
std::vector<char> BonesMovedBy(const Skeleton& skeleton, int joint) {
  std::vector<char> moved(skeleton.num_bones(), 0);
  for (int k : skeleton.BonesParentsFirst()) {
    const Bone& bone = skeleton.bone(k);
    moved[k] = bone.head_joint == joint || bone.tail_joint == joint ||
               (bone.parent_bone >= 0 && moved[bone.parent_bone] &&
                skeleton.bone(bone.parent_bone).tail_joint != joint);
  }
  return moved;
}

// The largest displacement (relative to the diagonal) of a vertex bound to a bone that `joint`
// does not move.
double StillPartMovement(const DeformationModel& model, const Frame& frame, int joint) {
  const std::vector<char> moved = BonesMovedBy(model.skeleton(), joint);
  double worst = 0;
  for (int i = 0; i < model.mesh().num_vertices(); ++i) {
    const int bone = model.bound_bones()[i];
    if (moved[bone]) continue;
    worst = std::max(worst, (frame.posed.row(i) - model.mesh().vertices.row(i)).norm());
  }
  return worst / model.bounding_box_diagonal();
}

TEST(RigBinding, LegsSideBySideBendOneKneeAndTheOtherLegStaysPut) {
  test_support::Rig rig = test_support::TwoLegsSideBySide();
  auto model = DeformationModel::Build(rig.mesh, rig.skeleton, ModelOptions::Paper());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  for (const char* spec : {"knee_b:flexion:90", "knee:flexion:90", "hip_b:x:40"}) {
    const Pose pose = PoseFromSpec((*model)->skeleton(), spec);
    const Frame frame = Deform(**model, pose);
    const int joint =
        *(*model)->skeleton().FindJoint(std::string(spec).substr(0, std::string(spec).find(':')));
    EXPECT_LT(RigidZoneError(**model, frame), 1e-3) << spec;
    EXPECT_LT(StillPartMovement(**model, frame, joint), 1e-3) << spec;
  }
  EXPECT_TRUE((*model)->binding_report().warnings.empty())
      << (*model)->binding_report().warnings.front();
}

TEST(RigBinding, StraightLineBindingWouldTearTheFixture) {
  // The same fixture bound by straight-line distance: leg A's inner side follows leg B's thigh.
  test_support::Rig rig = test_support::TwoLegsSideBySide();
  ModelOptions straight = ModelOptions::Paper();
  straight.binding = BindingMethod::kStraightLine;
  auto model = DeformationModel::Build(rig.mesh, rig.skeleton, straight);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  const Frame frame = Deform(**model, PoseFromSpec((*model)->skeleton(), "hip_b:x:40"));
  double leg_a_movement = 0;
  for (int i = 0; i < rig.first_leg_vertices; ++i) {
    leg_a_movement =
        std::max(leg_a_movement, (frame.posed.row(i) - rig.mesh.vertices.row(i)).norm());
  }
  EXPECT_GT(leg_a_movement / (*model)->bounding_box_diagonal(), 0.05);
  // ... and the report names the signature: leg B's shin zone has a piece far from the rest.
  EXPECT_FALSE((*model)->binding_report().warnings.empty());
}

TEST(RigBinding, TheArmsAuthoredWeightsKeepRigidZonesOnTheirBones) {
  DEFORM_REQUIRE_SHARED_FILE(mesh_path, "arm/arm_8311.obj");
  DEFORM_REQUIRE_SHARED_FILE(skeleton_path, "arm/arm.tgf");
  DEFORM_REQUIRE_SHARED_FILE(weights_path, "arm/arm_8311_weights.dmat");
  (void)weights_path;  // read through the model input in the deformctl test; here built in code
  auto mesh = ReadMeshFile(mesh_path);
  auto skeleton = ReadSkeletonFile(skeleton_path);
  ASSERT_TRUE(mesh.ok() && skeleton.ok());
  // The arm's harmonic binding as given weights: the model must reproduce itself through them.
  auto automatic = DeformationModel::Build(*mesh, *skeleton, ModelOptions::Paper());
  ASSERT_TRUE(automatic.ok()) << automatic.status().ToString();
  SkinWeights weights;
  weights.num_bones = skeleton->num_bones();
  const BoneWeights& harmonic = (*automatic)->bone_weights();
  for (int i = 0; i < mesh->num_vertices(); ++i) {
    std::vector<int> bones(harmonic.bones.begin() + harmonic.offsets[i],
                           harmonic.bones.begin() + harmonic.offsets[i + 1]);
    std::vector<double> values(harmonic.weights.begin() + harmonic.offsets[i],
                               harmonic.weights.begin() + harmonic.offsets[i + 1]);
    weights.AddVertex(bones, values);
  }
  auto normalized = NormalizeSkinWeights(weights, mesh->num_vertices(), skeleton->num_bones());
  ASSERT_TRUE(normalized.ok()) << normalized.status().ToString();
  auto given = DeformationModel::Build(*mesh, *skeleton, ModelOptions::Paper(), &*normalized);
  ASSERT_TRUE(given.ok()) << given.status().ToString();
  const Frame frame = Deform(**given, PoseFromSpec((*given)->skeleton(), "2:z:-90"));
  EXPECT_LT(RigidZoneError(**given, frame), 1e-3);
}

}  // namespace
}  // namespace deform
