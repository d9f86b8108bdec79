#include "core/model/weight_binding.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/io/rig_import.h"
#include "core/model/deformation_model.h"
#include "tests/core/io/gltf_test_util.h"

namespace deform {
namespace {

using gltf_test::ChainRig;
using gltf_test::PrimitiveData;

// A glTF character: the test tube (rigid on joint 0 below y = 1, on joint 1 above) and, as a
// second skinned node, a strap around it at y in [0.4, 0.6] weighted 0.75 / 0.25 to joints 0 and
// 1 everywhere: no vertex of the strap reaches 1 - rigid_weight_tolerance.
std::string TubeWithStrap() {
  const gltf_test::TestRig tube = gltf_test::Tube();
  PrimitiveData strap = gltf_test::RigidTubePrimitive(gltf_test::Tube(8, 2));
  for (std::size_t v = 0; v < strap.positions.size() / 3; ++v) {
    strap.positions[3 * v] *= 1.3f;
    strap.positions[3 * v + 1] = 0.4f + 0.1f * strap.positions[3 * v + 1];
    strap.positions[3 * v + 2] *= 1.3f;
    strap.joints[4 * v] = 0;
    strap.joints[4 * v + 1] = 1;
    strap.weights[4 * v] = 0.75f;
    strap.weights[4 * v + 1] = 0.25f;
  }
  gltf_test::GltfBuilder builder =
      ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {gltf_test::RigidTubePrimitive(tube)});
  builder.doc()["meshes"].push_back(
      {{"primitives", nlohmann::json::array({gltf_test::AddPrimitive(&builder, strap)})}});
  const int node = builder.AddNode({{"name", "strap"}, {"mesh", 1}, {"skin", 0}});
  builder.doc()["scenes"][0]["nodes"].push_back(node);
  return builder.ToGlb();
}

TEST(WeightBinding, APieceWithoutRigidVertexFollowsItsBestVertexsBone) {
  auto rig = ReadGltf(TubeWithStrap());
  ASSERT_TRUE(rig.ok()) << rig.status().ToString();
  ASSERT_EQ(rig->skinned_nodes.size(), 2u);
  const gltf_test::TestRig tube = gltf_test::Tube();
  const int strap_first = rig->skinned_nodes[1].first_file_vertex;
  auto model =
      DeformationModel::Build(rig->mesh, rig->skeleton, ModelOptions::Paper(), &rig->weights);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  for (int v = strap_first; v < static_cast<int>(rig->file_vertex_to_mesh.size()); ++v) {
    const int m = rig->file_vertex_to_mesh[static_cast<std::size_t>(v)];
    const int bone = (*model)->rigid_bones()[static_cast<std::size_t>(m)];
    ASSERT_GE(bone, 0) << "strap vertex " << v << " is not rigid";
    EXPECT_EQ((*model)->skeleton().joint((*model)->skeleton().bone(bone).head_joint).name,
              "joint0");
  }
  bool reported = false;
  for (const std::string& line : (*model)->binding_report().warnings) {
    reported |= line.find("1 connected piece(s)") != std::string::npos &&
                line.find("rigid_weight_tolerance") != std::string::npos;
  }
  EXPECT_TRUE(reported) << "no binding report line for the strap";
  // The tube's own rigid zones are as the tolerance says: none of its vertices changed.
  for (int v = 0; v < tube.mesh.num_vertices(); ++v) {
    const int m = rig->file_vertex_to_mesh[static_cast<std::size_t>(v)];
    EXPECT_GE((*model)->rigid_bones()[static_cast<std::size_t>(m)], 0) << v;
  }
}

}  // namespace
}  // namespace deform
