#include "core/io/model_input.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/io/gltf_writer.h"
#include "tests/core/io/gltf_test_util.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

TEST(LoadModelInput, ReadsAGltfRigWhole) {
  const gltf_test::TestRig tube = gltf_test::Tube();
  const std::string path =
      (std::filesystem::temp_directory_path() / "deform_model_input_test.glb").string();
  ASSERT_TRUE(WriteGltfFile(path, tube.mesh, tube.skeleton, tube.weights).ok());
  auto input = LoadModelInput(path, "", "", 0);
  auto with_skeleton = LoadModelInput(path, "leg.tgf", "", 0);
  auto with_weights = LoadModelInput(path, "", "w.dmat", 0);
  std::filesystem::remove(path);
  ASSERT_TRUE(input.ok()) << input.status().ToString();
  EXPECT_EQ(input->mesh.num_vertices(), tube.mesh.num_vertices());
  EXPECT_EQ(input->skeleton.num_bones(), 2);
  ASSERT_TRUE(input->weights.has_value());
  EXPECT_EQ(input->weights->num_vertices(), tube.mesh.num_vertices());
  EXPECT_EQ(input->file_vertex_to_mesh.size(), static_cast<std::size_t>(tube.mesh.num_vertices()));
  EXPECT_EQ(input->units, "metre");
  EXPECT_EQ(input->up_axis, "+Y");
  ASSERT_FALSE(with_skeleton.ok());
  EXPECT_NE(with_skeleton.status().message().find("its own skeleton"), std::string::npos);
  ASSERT_FALSE(with_weights.ok());
  EXPECT_NE(with_weights.status().message().find("its own skinning weights"), std::string::npos);
}

TEST(LoadModelInput, RefusesWeightsWithoutAMesh) {
  auto input = LoadModelInput("", "", "w.csv", 500);
  ASSERT_FALSE(input.ok());
  EXPECT_EQ(input.status().code(), StatusCode::kInvalidArgument);
  auto phantom = LoadModelInput("", "", 500);
  ASSERT_TRUE(phantom.ok()) << phantom.status().ToString();
  EXPECT_FALSE(phantom->weights.has_value());
  EXPECT_TRUE(phantom->file_vertex_to_mesh.empty());
}

TEST(LoadModelInput, ReadsAndChecksTheArmsWeights) {
  DEFORM_REQUIRE_SHARED_FILE(mesh, "arm/arm_8311.obj");
  DEFORM_REQUIRE_SHARED_FILE(skeleton, "arm/arm.tgf");
  DEFORM_REQUIRE_SHARED_FILE(weights, "arm/arm_8311_weights.dmat");
  DEFORM_REQUIRE_SHARED_FILE(other_weights, "arm/arm_33238_weights.dmat");
  auto input = LoadModelInput(mesh, skeleton, weights, 0);
  ASSERT_TRUE(input.ok()) << input.status().ToString();
  ASSERT_TRUE(input->weights.has_value());
  EXPECT_EQ(input->weights->num_vertices(), 8311);
  EXPECT_EQ(input->weights->num_bones, 4);
  auto mismatched = LoadModelInput(mesh, skeleton, other_weights, 0);
  ASSERT_FALSE(mismatched.ok());
  EXPECT_NE(mismatched.status().message().find("cover 33238 vertices; the mesh has 8311"),
            std::string::npos)
      << mismatched.status().message();
}

}  // namespace
}  // namespace deform
