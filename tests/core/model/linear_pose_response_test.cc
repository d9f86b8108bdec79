// METHOD.md's fast path: the linear rotation blend and its precomputed response.
#include "core/model/linear_pose_response.h"

#include <gtest/gtest.h>

#include <set>
#include <utility>
#include <vector>

#include "core/io/phantom.h"
#include "core/model/deformation_model.h"
#include "tests/allocation_counter.h"
#include "tests/core/model/model_test_util.h"
#include "tests/core/model/shared_leg_model.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

ModelOptions LinearBlend() {
  ModelOptions options = ModelOptions::Paper();
  options.rotation_blend = RotationBlend::kLinear;
  return options;
}

using test_support::MaxDistance;
using test_support::PoseFromSpec;

std::shared_ptr<const DeformationModel> BuildPhantomModel(const ModelOptions& options,
                                                          int vertices = 2000) {
  return test_support::BuildPhantomModel(vertices, options);
}

// The frame Deform() gives (from the response when the factorization has one).
Positions Frame(const DeformationModel& model, const MaterialFactorization& factorization,
                const Pose& pose) {
  DeformScratch scratch = model.MakeScratch();
  model.Deform(factorization, pose, &scratch);
  return scratch.positions();
}

// The same pose through the right-hand side and the two triangular solves.
Positions SolvedFrame(const DeformationModel& model, const MaterialFactorization& factorization,
                      const Pose& pose) {
  DeformScratch scratch = model.MakeScratch();
  model.AssembleRightHandSide(factorization, pose, &scratch);
  model.SolveInPlace(factorization, &scratch);
  return scratch.positions();
}

// A pose that bends and twists the knee and moves the whole limb.
Pose BentAndMoved(const Skeleton& skeleton) {
  Pose pose = PoseFromSpec(skeleton, "knee:flexion:100,knee:rotation:15,knee:varus_valgus:5");
  pose.root.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()));
  pose.root.translation = Eigen::Vector3d(0.3, 1.5, -2);
  return pose;
}

TEST(LinearPoseResponse, OnlyTheLinearBlendHasOne) {
  EXPECT_EQ(BuildPhantomModel(ModelOptions::Paper())->default_factorization()->linear_response(),
            nullptr);
  auto model = BuildPhantomModel(LinearBlend());
  const LinearPoseResponse* response = model->default_factorization()->linear_response();
  ASSERT_NE(response, nullptr);
  EXPECT_EQ(response->num_vertices(), model->mesh().num_vertices());
  EXPECT_EQ(response->bones().size(), 2u);  // thigh and shank
  // The knee's pair blend in 4 segments: 3 interior knots, shares (3, 1), (2, 2), (1, 3).
  ASSERT_EQ(response->num_knots(), 3);
  std::set<std::vector<std::pair<int, int>>> knots;
  for (int j = 0; j < 3; ++j) knots.insert(model->linear_blend_plan()->KnotShares(j));
  EXPECT_EQ(knots, (std::set<std::vector<std::pair<int, int>>>{
                       {{0, 3}, {1, 1}}, {{0, 2}, {1, 2}}, {{0, 1}, {1, 3}}}));
  // 4 vectors per bone, 3 per knot.
  EXPECT_EQ(response->bytes(), (4 * 2 + 3 * 3) * sizeof(double) * model->mesh().num_vertices());
}

TEST(LinearPoseResponse, EqualsTheSolveWithTheLinearBlend) {
  auto model = BuildPhantomModel(LinearBlend());
  const auto& factorization = *model->default_factorization();
  const Pose pose = BentAndMoved(model->skeleton());
  const Positions fast = Frame(*model, factorization, pose);
  const Positions solved = SolvedFrame(*model, factorization, pose);
  EXPECT_LT(MaxDistance(fast, solved), 1e-10 * model->bounding_box_diagonal());
  // Not trivially: the pose moves the mesh far from its rest shape.
  EXPECT_GT(MaxDistance(fast, model->mesh().vertices), 0.1 * model->bounding_box_diagonal());
}

TEST(LinearPoseResponse, IsRebuiltForANewStiffness) {
  auto model = BuildPhantomModel(LinearBlend());
  Stiffness stiffness;
  stiffness.joint_materials.push_back({1, JointMaterial{9.0, 0.3, 6.0}});  // the knee
  stiffness.vertex_weights = {{7, 20.0}};
  auto refactored = model->Factorize(stiffness);
  ASSERT_TRUE(refactored.ok()) << refactored.status().ToString();
  ASSERT_NE((*refactored)->linear_response(), nullptr);
  const Pose pose = BentAndMoved(model->skeleton());
  const Positions fast = Frame(*model, **refactored, pose);
  EXPECT_LT(MaxDistance(fast, SolvedFrame(*model, **refactored, pose)),
            1e-10 * model->bounding_box_diagonal());
  EXPECT_GT(MaxDistance(fast, Frame(*model, *model->default_factorization(), pose)),
            1e-6 * model->bounding_box_diagonal());
}

TEST(LinearPoseResponse, RestAndRigidMotionsAreExact) {
  auto model = BuildPhantomModel(LinearBlend());
  const auto& factorization = *model->default_factorization();
  const double diagonal = model->bounding_box_diagonal();
  EXPECT_LT(MaxDistance(Frame(*model, factorization, Pose::Rest(model->skeleton())),
                        model->mesh().vertices),
            1e-9 * diagonal);
  Pose moved = Pose::Rest(model->skeleton());
  moved.root.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(2.0, Eigen::Vector3d::UnitY()));
  moved.root.translation = Eigen::Vector3d(4, 0, -1);
  Positions expected = model->mesh().vertices;
  for (int i = 0; i < expected.rows(); ++i) {
    expected.row(i) = moved.root.Apply(expected.row(i).transpose()).transpose();
  }
  EXPECT_LT(MaxDistance(Frame(*model, factorization, moved), expected), 1e-9 * diagonal);
}

// METHOD.md's plain linear blend is not the quaternion blend: where bones blend, T_i = sum h R_k
// shrinks (at 90 degrees and h = 1/2 its scale is cos 45 = 0.71), so the two methods part there
// and agree far from the knee.
TEST(LinearPoseResponse, PlainLinearBlendDiffersFromTheQuaternionBlendOnlyNearTheJoint) {
  ModelOptions plain = LinearBlend();
  plain.linear_blend_segments = 1;
  auto linear = BuildPhantomModel(plain);
  ASSERT_TRUE(linear->default_factorization()->linear_response()->num_knots() == 0);
  auto quaternion = BuildPhantomModel(ModelOptions::Paper());
  const Pose pose = PoseFromSpec(linear->skeleton(), "knee:flexion:90");
  const Positions a = Frame(*linear, *linear->default_factorization(), pose);
  const Positions b = Frame(*quaternion, *quaternion->default_factorization(), pose);
  const double diagonal = linear->bounding_box_diagonal();
  EXPECT_GT(MaxDistance(a, b), 1e-3 * diagonal);
  double anchors_apart = 0;
  for (int i : linear->anchor_vertices()) {
    anchors_apart = std::max(anchors_apart, (a.row(i) - b.row(i)).norm());
  }
  EXPECT_LT(anchors_apart, 1e-3 * diagonal);
}

// More segments along each pair's quaternion blend bring the frame closer to the quaternion
// blend's: the blended matrix's shrink, 1 - cos(90 / 2 S degrees), falls about four times per
// doubling.
TEST(LinearPoseResponse, MoreSegmentsApproachTheQuaternionBlend) {
  auto quaternion = BuildPhantomModel(ModelOptions::Paper());
  const Pose pose = PoseFromSpec(quaternion->skeleton(), "knee:flexion:90");
  const Positions reference = Frame(*quaternion, *quaternion->default_factorization(), pose);
  std::vector<double> distances;
  for (int segments : {1, 2, 4, 8}) {
    ModelOptions options = LinearBlend();
    options.linear_blend_segments = segments;
    auto model = BuildPhantomModel(options);
    const auto& factorization = *model->default_factorization();
    ASSERT_NE(factorization.linear_response(), nullptr);
    const Positions fast = Frame(*model, factorization, pose);
    EXPECT_LT(MaxDistance(fast, SolvedFrame(*model, factorization, pose)),
              1e-10 * model->bounding_box_diagonal());
    distances.push_back(MaxDistance(fast, reference));
  }
  for (std::size_t k = 1; k < distances.size(); ++k) {
    EXPECT_LT(distances[k], 0.5 * distances[k - 1]) << "segments " << (1 << k);
  }
  EXPECT_LT(distances.back(), 0.05 * distances.front());
}

TEST(LinearPoseResponse, AFrameAllocatesNothing) {
  auto model = BuildPhantomModel(LinearBlend());
  const Pose pose = PoseFromSpec(model->skeleton(), "knee:flexion:45");
  DeformScratch scratch = model->MakeScratch();
  DeformTimings timings;
  model->Deform(*model->default_factorization(), pose, &scratch, &timings);
  const long before = test_support::AllocationCount();
  for (int frame = 0; frame < 10; ++frame) {
    model->Deform(*model->default_factorization(), pose, &scratch, &timings);
  }
  EXPECT_EQ(test_support::AllocationCount() - before, 0);
}

TEST(LinearPoseResponse, EqualsTheSolveOnTheSharedLeg) {
  DEFORM_REQUIRE_SHARED_FILE(mesh_path, "leg/leg_1633.obj");
  DEFORM_REQUIRE_SHARED_FILE(skeleton_path, "leg/leg.tgf");
  auto model = test_support::BuildModelFromFiles(mesh_path, skeleton_path, LinearBlend());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  const auto& factorization = *(*model)->default_factorization();
  ASSERT_NE(factorization.linear_response(), nullptr);
  const Pose pose = PoseFromSpec((*model)->skeleton(), "1:x:120,2:x:-20");
  EXPECT_LT(
      MaxDistance(Frame(**model, factorization, pose), SolvedFrame(**model, factorization, pose)),
      1e-10 * (*model)->bounding_box_diagonal());
}

// Where the response would hold at least twice the factor's non-zeros (many bones on few
// vertices), frames solve instead.
TEST(LinearPoseResponse, ManyBonesSolveInstead) {
  DEFORM_REQUIRE_SHARED_FILE(mesh_path, "body/body_13380.obj");
  DEFORM_REQUIRE_SHARED_FILE(skeleton_path, "body/body.tgf");
  auto model = test_support::BuildModelFromFiles(mesh_path, skeleton_path, LinearBlend());
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  EXPECT_EQ((*model)->default_factorization()->linear_response(), nullptr);
  const Positions rest =
      Frame(**model, *(*model)->default_factorization(), Pose::Rest((*model)->skeleton()));
  EXPECT_LT(MaxDistance(rest, (*model)->mesh().vertices), 1e-6 * (*model)->bounding_box_diagonal());
}

TEST(LinearPoseResponse, RefusesSegmentsOutOfRange) {
  auto phantom = MakeKneePhantom(400);
  ASSERT_TRUE(phantom.ok());
  for (int segments : {0, -3, ModelOptions::kMaxLinearBlendSegments + 1}) {
    ModelOptions options = LinearBlend();
    options.linear_blend_segments = segments;
    auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, options);
    ASSERT_FALSE(model.ok()) << segments;
    EXPECT_EQ(model.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(model.status().message().find("linear_blend_segments"), std::string::npos);
  }
}

}  // namespace
}  // namespace deform
