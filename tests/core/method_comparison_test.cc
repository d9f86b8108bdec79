// The contract of the method (METHOD.md): at 90 and 120 degrees of knee flexion it beats plain
// Laplacian deformation and linear blend skinning on skin-to-bone clearance and volume; so does its
// fast path with the default four-segment linear blend (paper-linear).
#include "core/method_comparison.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/mesh_io.h"
#include "core/phantom.h"
#include "tests/core/shared_leg_model.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

void ExpectPaperBeatsBaselines(const DeformationModel& model, const std::string& knee_axis) {
  for (double degrees : {90.0, 120.0}) {
    Pose pose;
    auto terms = ParsePoseSpec(knee_axis + ":" + std::to_string(degrees), model.skeleton());
    ASSERT_TRUE(terms.ok());
    ASSERT_TRUE(PoseFromTerms(model.skeleton(), *terms, &pose).ok());
    for (Method method : {Method::kPaper, Method::kPaperLinear}) {
      auto paper = RunMethod(model, method, pose);
      ASSERT_TRUE(paper.ok()) << paper.status().ToString();
      for (Method baseline : {Method::kLaplacian, Method::kLbs}) {
        auto other = RunMethod(model, baseline, pose);
        ASSERT_TRUE(other.ok()) << other.status().ToString();
        SCOPED_TRACE(std::string(MethodName(method)) + " against " + MethodName(baseline) +
                     " at " + std::to_string(degrees));
        EXPECT_GT(paper->quality.clearance.min, other->quality.clearance.min);
        EXPECT_LT(std::abs(paper->quality.volume_change), std::abs(other->quality.volume_change));
      }
    }
  }
}

TEST(MethodComparison, PaperBeatsLaplacianAndLbsOnThePhantom) {
  auto phantom = MakeKneePhantom();
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, ModelOptions::Paper());
  ASSERT_TRUE(model.ok());
  ExpectPaperBeatsBaselines(**model, "knee:flexion");
}

TEST(MethodComparison, PaperBeatsLaplacianAndLbsOnTheSharedLeg) {
  DEFORM_SHARED_LEG_MODEL(model);
  ExpectPaperBeatsBaselines(*model, "1:x");
}

TEST(MethodComparison, EveryMethodReproducesTheRestPose) {
  auto phantom = MakeKneePhantom(800);
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, ModelOptions::Paper());
  ASSERT_TRUE(model.ok());
  for (Method m :
       {Method::kPaper, Method::kPaperLinear, Method::kLaplacian, Method::kLbs, Method::kDqs}) {
    auto run = RunMethod(**model, m, Pose::Rest(phantom->skeleton));
    ASSERT_TRUE(run.ok());
    EXPECT_LT(run->quality.max_displacement, 1e-9) << MethodName(m);
    EXPECT_NEAR(run->quality.volume_change, 0, 1e-9) << MethodName(m);
  }
}

TEST(MethodComparison, MethodNamesRoundTrip) {
  for (Method m :
       {Method::kPaper, Method::kPaperLinear, Method::kLaplacian, Method::kLbs, Method::kDqs}) {
    EXPECT_EQ(*MethodFromName(MethodName(m)), m);
  }
  EXPECT_EQ(MethodFromName("arap").status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace deform
