// The paper's model of the shared 1.6k leg, for tests that check the method on real data.
//
// DEFORM_SHARED_LEG_MODEL(model) declares `model` (shared_ptr<const DeformationModel>) built from
// ../shared/data/leg/leg_1633.obj and leg.tgf, or skips the test where they are absent.
#pragma once

#include <memory>
#include <string>

#include "core/io/mesh_io.h"
#include "core/io/skeleton_io.h"
#include "core/model/deformation_model.h"
#include "tests/shared_data.h"

namespace deform::test_support {

inline StatusOr<std::shared_ptr<const DeformationModel>> BuildModelFromFiles(
    const std::string& mesh_path, const std::string& skeleton_path,
    const ModelOptions& options = ModelOptions::Paper()) {
  DEFORM_ASSIGN_OR_RETURN(TriangleMesh mesh, ReadMeshFile(mesh_path));
  DEFORM_ASSIGN_OR_RETURN(Skeleton skeleton, ReadSkeletonFile(skeleton_path));
  return DeformationModel::Build(std::move(mesh), std::move(skeleton), options);
}

}  // namespace deform::test_support

#define DEFORM_SHARED_LEG_MODEL(model)                                                       \
  DEFORM_REQUIRE_SHARED_FILE(model##_mesh_path, "leg/leg_1633.obj");                         \
  DEFORM_REQUIRE_SHARED_FILE(model##_skeleton_path, "leg/leg.tgf");                          \
  auto model##_or =                                                                          \
      ::deform::test_support::BuildModelFromFiles(model##_mesh_path, model##_skeleton_path); \
  ASSERT_TRUE(model##_or.ok()) << model##_or.status().ToString();                            \
  const std::shared_ptr<const ::deform::DeformationModel> model = *model##_or
