// Helpers shared by the deformation model's tests: a phantom model, poses from specs, distances.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "core/io/phantom.h"
#include "core/model/deformation_model.h"

namespace deform::test_support {

inline std::shared_ptr<const DeformationModel> BuildPhantomModel(
    int vertices = 2000, const ModelOptions& options = ModelOptions::Paper()) {
  auto phantom = MakeKneePhantom(vertices);
  EXPECT_TRUE(phantom.ok());
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, options);
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  return model.ok() ? *model : nullptr;
}

inline Pose PoseFromSpec(const Skeleton& skeleton, const std::string& spec) {
  Pose pose;
  auto terms = ParsePoseSpec(spec, skeleton);
  EXPECT_TRUE(terms.ok()) << terms.status().ToString();
  EXPECT_TRUE(PoseFromTerms(skeleton, *terms, &pose).ok());
  return pose;
}

// The largest distance between corresponding rows.
inline double MaxDistance(const Positions& a, const Positions& b) {
  return (a - b).rowwise().norm().maxCoeff();
}

}  // namespace deform::test_support
