// The contract of the method (METHOD.md): at 90 and 120 degrees of knee flexion it beats plain
// Laplacian deformation and linear blend skinning on skin-to-bone clearance and volume; so does its
// fast path with the default four-segment linear blend (paper-linear).
#include "core/eval/method_comparison.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "tests/core/model/model_test_util.h"
#include "tests/core/model/shared_leg_model.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

using test_support::BuildPhantomModel;
using test_support::PoseFromSpec;

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
        SCOPED_TRACE(std::string(MethodName(method)) + " against " + MethodName(baseline) + " at " +
                     std::to_string(degrees));
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
  for (Method m : {Method::kPaper, Method::kPaperLinear, Method::kLaplacian, Method::kLbs,
                   Method::kDqs, Method::kCor, Method::kDdm}) {
    auto run = RunMethod(**model, m, Pose::Rest(phantom->skeleton));
    ASSERT_TRUE(run.ok());
    EXPECT_LT(run->quality.max_displacement, 1e-9) << MethodName(m);
    EXPECT_NEAR(run->quality.volume_change, 0, 1e-9) << MethodName(m);
    EXPECT_EQ(run->quality.inverted_triangles, 0) << MethodName(m);
    EXPECT_EQ(run->quality.self_intersections, 0) << MethodName(m);
  }
}

TEST(MethodComparison, MethodNamesRoundTrip) {
  for (Method m : {Method::kPaper, Method::kPaperLinear, Method::kLaplacian, Method::kLbs,
                   Method::kDqs, Method::kCor, Method::kDdm}) {
    EXPECT_EQ(*MethodFromName(MethodName(m)), m);
  }
  EXPECT_EQ(MethodFromName("arap").status().code(), StatusCode::kInvalidArgument);
}

TEST(MethodComparison, PaperLinearIsAMethod) {
  auto model = BuildPhantomModel(800);
  auto run =
      RunMethod(*model, Method::kPaperLinear, PoseFromSpec(model->skeleton(), "knee:flexion:60"));
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  EXPECT_GT(run->response_bytes, 0u);
  EXPECT_EQ(*MethodFromName("paper-linear"), Method::kPaperLinear);
}

}  // namespace
}  // namespace deform
