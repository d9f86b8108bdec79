// The deformation model with cotangent and intrinsic Delaunay cotangent Laplacian weights
// (ModelOptions::laplacian): the rest pose and rigid motions come out exactly, the row pattern
// of the intrinsic triangulation reaches the factor and the right-hand side, and the harmonic
// bone weights stay uniform.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <string>

#include "core/model/deformation_model.h"
#include "tests/core/model/model_test_util.h"
#include "tests/core/model/shared_leg_model.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

using test_support::BuildPhantomModel;
using test_support::MaxDistance;
using test_support::PoseFromSpec;

ModelOptions WithWeights(LaplacianWeights kind, RotationBlend blend = RotationBlend::kQuaternion) {
  ModelOptions options = ModelOptions::Paper();
  options.laplacian = kind;
  options.rotation_blend = blend;
  return options;
}

Positions DeformOnce(const DeformationModel& model, const Pose& pose) {
  DeformScratch scratch = model.MakeScratch();
  EXPECT_TRUE(model.Deform(*model.default_factorization(), pose, &scratch));
  return scratch.positions();
}

class LaplacianWeightsModelTest : public testing::TestWithParam<LaplacianWeights> {};

TEST(LaplacianWeightsModel, TheDefaultIsUniform) {
  EXPECT_EQ(ModelOptions::Paper().laplacian, LaplacianWeights::kUniform);
  auto model = BuildPhantomModel(300);
  EXPECT_EQ(model->laplacian_weight_report().kind, LaplacianWeights::kUniform);
  EXPECT_EQ(model->laplacian_weight_report().flips, 0);
}

TEST_P(LaplacianWeightsModelTest, RestPoseReproducesThePhantomForBothRotationBlends) {
  for (const RotationBlend blend : {RotationBlend::kQuaternion, RotationBlend::kLinear}) {
    auto model = BuildPhantomModel(2000, WithWeights(GetParam(), blend));
    ASSERT_NE(model, nullptr);
    EXPECT_EQ(model->laplacian_weight_report().kind, GetParam());
    const Positions posed = DeformOnce(*model, Pose::Rest(model->skeleton()));
    EXPECT_LT(MaxDistance(posed, model->mesh().vertices), 1e-9 * model->bounding_box_diagonal());
  }
}

TEST_P(LaplacianWeightsModelTest, RestPoseReproducesTheSharedLeg) {
  DEFORM_REQUIRE_SHARED_FILE(mesh_path, "leg/leg_1633.obj");
  DEFORM_REQUIRE_SHARED_FILE(skeleton_path, "leg/leg.tgf");
  auto model = test_support::BuildModelFromFiles(mesh_path, skeleton_path, WithWeights(GetParam()));
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  const Positions posed = DeformOnce(**model, Pose::Rest((*model)->skeleton()));
  EXPECT_LT(MaxDistance(posed, (*model)->mesh().vertices),
            1e-5 * (*model)->bounding_box_diagonal());
}

TEST_P(LaplacianWeightsModelTest, RigidMotionOfTheSkeletonMovesTheMeshRigidly) {
  auto model = BuildPhantomModel(2000, WithWeights(GetParam()));
  Pose pose = Pose::Rest(model->skeleton());
  pose.root.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  pose.root.translation = Eigen::Vector3d(0.5, -2, 3);
  const Positions posed = DeformOnce(*model, pose);
  Positions expected(model->mesh().num_vertices(), 3);
  for (int i = 0; i < expected.rows(); ++i) {
    expected.row(i) = pose.root.Apply(model->mesh().vertices.row(i).transpose()).transpose();
  }
  EXPECT_LT(MaxDistance(posed, expected), 1e-9 * model->bounding_box_diagonal());
}

TEST_P(LaplacianWeightsModelTest, RigidZonesFollowTheirBonesAtNinetyDegrees) {
  auto model = BuildPhantomModel(2000, WithWeights(GetParam()));
  const Pose pose = PoseFromSpec(model->skeleton(), "knee:flexion:90");
  const Positions posed = DeformOnce(*model, pose);
  std::vector<RigidTransform> bones;
  ForwardKinematics(model->skeleton(), pose, &bones);
  double worst = 0;
  for (int i = 0; i < model->mesh().num_vertices(); ++i) {
    const int bone = model->rigid_bones()[i];
    if (bone < 0) continue;
    const Eigen::Vector3d target = bones[bone].Apply(model->mesh().vertices.row(i).transpose());
    worst = std::max(worst, (posed.row(i).transpose() - target).norm());
  }
  EXPECT_LT(worst, 1e-4 * model->bounding_box_diagonal());
}

// The factor and the right-hand side's rigid and general rows take L''s actual pattern: with
// flips it has entries outside the one-ring, and the sparse solve of the assembled right-hand side
// equals a dense solve of the normal equations.
TEST_P(LaplacianWeightsModelTest, SparseSolveMatchesADenseSolve) {
  auto model = BuildPhantomModel(300, WithWeights(GetParam()));
  if (GetParam() == LaplacianWeights::kIntrinsicCotangent) {
    EXPECT_GT(model->laplacian_weight_report().new_neighbor_pairs, 0);
  }
  const auto& factorization = *model->default_factorization();
  const Pose pose = PoseFromSpec(model->skeleton(), "knee:flexion:70,knee:rotation:10");
  DeformScratch scratch = model->MakeScratch();
  ASSERT_TRUE(model->AssembleRightHandSide(factorization, pose, &scratch));
  const Eigen::MatrixXd rhs = scratch.solution;
  ASSERT_TRUE(model->SolveInPlace(factorization, &scratch));
  const Eigen::MatrixXd dense = Eigen::MatrixXd(model->NormalMatrix(factorization));
  const Eigen::MatrixXd expected = dense.llt().solve(rhs);
  EXPECT_LT((Eigen::MatrixXd(scratch.solution) - expected).norm(), 1e-9 * expected.norm());
}

TEST_P(LaplacianWeightsModelTest, TheHarmonicBoneWeightsStayUniform) {
  auto uniform = BuildPhantomModel(2000);
  auto other = BuildPhantomModel(2000, WithWeights(GetParam()));
  EXPECT_EQ(other->bone_weights().dense, uniform->bone_weights().dense);
  EXPECT_EQ(other->rigid_bones(), uniform->rigid_bones());
}

INSTANTIATE_TEST_SUITE_P(CotangentAndIntrinsic, LaplacianWeightsModelTest,
                         testing::Values(LaplacianWeights::kCotangent,
                                         LaplacianWeights::kIntrinsicCotangent),
                         [](const testing::TestParamInfo<LaplacianWeights>& info) {
                           return std::string(LaplacianWeightsName(info.param));
                         });

}  // namespace
}  // namespace deform
