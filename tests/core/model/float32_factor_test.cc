// The float32 factor (ModelOptions::float32_factor_min_bytes): when it is used, what its frames
// differ by, and the probe that keeps a factor in double where its rounding would show.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/model/deformation_model.h"
#include "tests/core/model/model_test_util.h"
#include "tests/core/model/shared_leg_model.h"

namespace deform {
namespace {

using test_support::BuildPhantomModel;
using test_support::MaxDistance;
using test_support::PoseFromSpec;

ModelOptions Float32Options(std::int64_t min_bytes = 0) {
  ModelOptions options = ModelOptions::Paper();
  options.float32_factor_min_bytes = min_bytes;
  return options;
}

Positions DeformOnce(const DeformationModel& model, const Pose& pose,
                     const MaterialFactorization& factorization) {
  DeformScratch scratch = model.MakeScratch();
  EXPECT_TRUE(model.Deform(factorization, pose, &scratch));
  return scratch.positions();
}

// The same phantom with a double and a float32 factor: the float32 factor holds half the values'
// bytes, its probe error is reported, and every pose's frame differs from the double frame by
// less than 1e-6 of the diagonal (the float32 transport's own rounding), and not by nothing.
TEST(Float32Factor, FramesStayWithinTheTransportRoundingOfTheDoubleFrames) {
  auto exact = BuildPhantomModel(2000);
  auto rounded = BuildPhantomModel(2000, Float32Options());
  const MaterialFactorization& rounded_factorization = *rounded->default_factorization();
  ASSERT_TRUE(rounded_factorization.factor().stores_float32());
  EXPECT_FALSE(exact->default_factorization()->factor().stores_float32());
  EXPECT_LT(exact->default_factorization()->float32_probe_error(), 0);  // no probe ran
  EXPECT_GT(rounded_factorization.float32_probe_error(), 0);
  EXPECT_LE(rounded_factorization.float32_probe_error(),
            MaterialFactorization::kFloat32ProbeTolerance);
  EXPECT_LT(rounded_factorization.factor().bytes(),
            0.7 * exact->default_factorization()->factor().bytes());
  // A refactorization is built in double: that is what it holds while it runs.
  EXPECT_EQ(rounded->FactorizationBytes(), exact->FactorizationBytes());
  const double diagonal = exact->bounding_box_diagonal();
  for (const char* spec : {"knee:flexion:0", "knee:flexion:45", "knee:flexion:120",
                           "knee:flexion:60,knee:rotation:15,knee:varus_valgus:8"}) {
    const Pose pose = PoseFromSpec(exact->skeleton(), spec);
    const double difference =
        MaxDistance(DeformOnce(*rounded, pose, rounded_factorization),
                    DeformOnce(*exact, pose, *exact->default_factorization()));
    EXPECT_LT(difference, 1e-6 * diagonal) << spec;
    EXPECT_GT(difference, 1e-12 * diagonal) << spec << ": the float32 values were not used";
  }
  // A factorization for other stiffness is probed and rounded too.
  Stiffness stiffer;
  stiffer.joint_materials.push_back({1, JointMaterial{9.0, 2.5, 6.0}});  // the knee
  auto other = rounded->Factorize(stiffer);
  ASSERT_TRUE(other.ok()) << other.status().ToString();
  EXPECT_TRUE((*other)->factor().stores_float32());
  auto other_exact = exact->Factorize(stiffer);
  ASSERT_TRUE(other_exact.ok()) << other_exact.status().ToString();
  const Pose pose = PoseFromSpec(exact->skeleton(), "knee:flexion:90");
  EXPECT_LT(
      MaxDistance(DeformOnce(*rounded, pose, **other), DeformOnce(*exact, pose, **other_exact)),
      1e-6 * diagonal);
}

// Batched and parallel frames of a float32 factor equal its own serial frames to 1e-12 of the
// diagonal: every path reads the same rounded values.
TEST(Float32Factor, BatchedAndParallelFramesEqualTheSerialFrame) {
  auto model = BuildPhantomModel(2000, Float32Options());
  const MaterialFactorization& factorization = *model->default_factorization();
  ASSERT_TRUE(factorization.factor().stores_float32());
  const double tolerance = 1e-12 * model->bounding_box_diagonal();
  std::vector<Pose> poses;
  std::vector<DeformScratch> scratches;
  std::vector<const Pose*> pose_pointers;
  std::vector<DeformScratch*> scratch_pointers;
  for (int f = 0; f < 4; ++f) {
    poses.push_back(PoseFromSpec(model->skeleton(), "knee:flexion:" + std::to_string(30 * f)));
    scratches.push_back(model->MakeScratch());
  }
  for (int f = 0; f < 4; ++f) {
    pose_pointers.push_back(&poses[f]);
    scratch_pointers.push_back(&scratches[f]);
  }
  DeformBatchScratch batch = model->MakeBatchScratch(4);
  ASSERT_TRUE(
      model->DeformBatch(factorization, pose_pointers.data(), scratch_pointers.data(), 4, &batch));
  const ParallelSolvePlan plan = factorization.factor().PlanParallel(2);
  ASSERT_EQ(plan.parts, 2);
  std::vector<double> work(factorization.factor().WorkSizeParallel(plan));
  ThreadTeam team(2);
  for (int f = 0; f < 4; ++f) {
    const Positions serial = DeformOnce(*model, poses[f], factorization);
    EXPECT_LE(MaxDistance(scratches[f].positions(), serial), tolerance) << "batch frame " << f;
    DeformScratch scratch = model->MakeScratch();
    ASSERT_TRUE(model->DeformParallel(factorization, poses[f], &scratch, plan, work.data(), &team));
    EXPECT_LE(MaxDistance(scratch.positions(), serial), tolerance) << "parallel frame " << f;
  }
}

// Only factors of at least float32_factor_min_bytes are probed; a negative value (the default)
// never rounds.
TEST(Float32Factor, OnlyFactorsOfTheGivenSizeAreRounded) {
  auto model = BuildPhantomModel(2000, Float32Options(std::int64_t{1} << 40));
  EXPECT_FALSE(model->default_factorization()->factor().stores_float32());
  EXPECT_LT(model->default_factorization()->float32_probe_error(), 0);
  EXPECT_EQ(ModelOptions::Paper().float32_factor_min_bytes, -1);
}

// Anchors this weak leave the system so ill-conditioned that the factor's float32 rounding moves
// the rest pose by more than the probe's tolerance (about 2e-6 of the diagonal, beyond the 1e-6
// frames may differ by): the factor stays double and the probe's error is reported.
TEST(Float32Factor, AFactorWhoseRoundingShowsStaysDouble) {
  ModelOptions options = Float32Options();
  options.anchor_weight = 1e-4;
  auto model = BuildPhantomModel(2000, options);
  const MaterialFactorization& factorization = *model->default_factorization();
  EXPECT_FALSE(factorization.factor().stores_float32());
  EXPECT_GT(factorization.float32_probe_error(), MaterialFactorization::kFloat32ProbeTolerance);
}

// The shared 1.6k leg: the float32 factor's frames within 1e-6 of the diagonal from 0 to 120
// degrees of knee flexion.
TEST(Float32Factor, TheSharedLegStaysWithinTheTransportRounding) {
  DEFORM_SHARED_LEG_MODEL(exact);
  DEFORM_REQUIRE_SHARED_FILE(mesh_path, "leg/leg_1633.obj");
  DEFORM_REQUIRE_SHARED_FILE(skeleton_path, "leg/leg.tgf");
  auto rounded = test_support::BuildModelFromFiles(mesh_path, skeleton_path, Float32Options());
  ASSERT_TRUE(rounded.ok()) << rounded.status().ToString();
  ASSERT_TRUE((*rounded)->default_factorization()->factor().stores_float32());
  for (const int degrees : {0, 30, 60, 90, 120}) {
    const Pose pose = PoseFromSpec(exact->skeleton(), "1:x:" + std::to_string(degrees));
    EXPECT_LT(MaxDistance(DeformOnce(**rounded, pose, *(*rounded)->default_factorization()),
                          DeformOnce(*exact, pose, *exact->default_factorization())),
              1e-6 * exact->bounding_box_diagonal())
        << degrees;
  }
}

}  // namespace
}  // namespace deform
