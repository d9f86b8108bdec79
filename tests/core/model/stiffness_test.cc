#include "core/model/stiffness.h"

#include <gtest/gtest.h>

#include <limits>

#include "tests/core/model/model_test_util.h"

namespace deform {
namespace {

TEST(CheckMaterialWeight, AcceptsFinitePositiveWeightsUpToTheMaximum) {
  EXPECT_TRUE(CheckMaterialWeight(1e-6, "w").ok());
  EXPECT_TRUE(CheckMaterialWeight(kMaxMaterialWeight, "w").ok());
  for (double bad : {0.0, -1.0, kMaxMaterialWeight * 2, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    const Status status = CheckMaterialWeight(bad, "weight of vertex 3");
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << bad;
    EXPECT_EQ(status.message().rfind("weight of vertex 3 must be finite and in (0, ", 0), 0u)
        << status.message();
  }
}

TEST(CheckJointMaterial, NamesTheWeightAtFault) {
  EXPECT_TRUE(CheckJointMaterial(JointMaterial{}, "knee").ok());
  EXPECT_EQ(CheckJointMaterial({4, 1, -1}, "knee").message().rfind("knee seam weight must", 0), 0u);
}

TEST(RegionOfJoint, OnlyInnerJointsHaveARegion) {
  auto model = test_support::BuildPhantomModel(600);
  const JointRegions& regions = model->joint_regions();
  EXPECT_EQ(FindJointRegion(regions, 1), 0);  // the knee
  EXPECT_EQ(FindJointRegion(regions, 0), -1);
  EXPECT_EQ(FindJointRegion(regions, 99), -1);
  EXPECT_EQ(*RegionOfJoint(regions, model->skeleton(), 1), 0);
  EXPECT_EQ(RegionOfJoint(regions, model->skeleton(), 0).status().message(),
            "joint 'hip' has no joint region (only inner joints have one)");
  EXPECT_EQ(RegionOfJoint(regions, model->skeleton(), 99).status().message(),
            "joint 99 has no joint region (only inner joints have one)");
}

}  // namespace
}  // namespace deform
