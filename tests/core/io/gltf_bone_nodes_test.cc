// Bone surfaces a glTF character carries as unskinned mesh nodes under its joints (rig_import.h,
// "Bone surfaces"): taken when they are bones, left out with a warning when they are props.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry/enclosed_volume.h"
#include "core/geometry/mesh_topology.h"
#include "core/geometry/primitive_surfaces.h"
#include "core/io/gltf_writer.h"
#include "core/io/rig_import.h"
#include "gltf_test_util.h"

namespace deform {
namespace {

using gltf_test::AddPrimitive;
using gltf_test::Bytes;
using gltf_test::ChainRig;
using gltf_test::GltfBuilder;
using gltf_test::kFloat;
using gltf_test::kUnsignedInt;
using gltf_test::RigidTubePrimitive;
using gltf_test::Tube;

// An axis-aligned box of half size `half` at `centre`, four vertices per face (split as an
// exporter splits them for normals), outward unless `inward`; `drop_last` leaves one triangle
// out (an open box).
nlohmann::json BoxPrimitive(GltfBuilder* builder, const Eigen::Vector3d& centre, double half,
                            bool inward = false, bool drop_last = false) {
  std::vector<float> positions;
  std::vector<std::uint32_t> indices;
  for (int axis = 0; axis < 3; ++axis) {
    for (int side : {-1, 1}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const std::uint32_t first = static_cast<std::uint32_t>(positions.size() / 3);
      constexpr std::array<std::array<int, 2>, 4> kCorners = {{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}};
      for (const auto& [a, b] : kCorners) {
        Eigen::Vector3d p = centre;
        p[axis] += side * half;
        p[u] += a * half;
        p[v] += b * half;
        for (int c = 0; c < 3; ++c) positions.push_back(static_cast<float>(p[c]));
      }
      // (u, v, axis) is right-handed: counter-clockwise in (u, v) faces +axis.
      const bool forward = (side > 0) != inward;
      constexpr std::array<std::array<std::uint32_t, 3>, 2> kHalves = {{{0, 1, 2}, {0, 2, 3}}};
      for (const auto& t : kHalves) {
        indices.push_back(first + t[0]);
        indices.push_back(first + (forward ? t[1] : t[2]));
        indices.push_back(first + (forward ? t[2] : t[1]));
      }
    }
  }
  if (drop_last) indices.resize(indices.size() - 3);
  nlohmann::json attributes;
  attributes["POSITION"] = builder->AddAccessor(Bytes(positions), kFloat, "VEC3",
                                                static_cast<int>(positions.size() / 3));
  return {{"attributes", attributes},
          {"indices", builder->AddAccessor(Bytes(indices), kUnsignedInt, "SCALAR",
                                           static_cast<int>(indices.size()))}};
}

// Adds a mesh of one primitive and a node holding it, as a child of node `parent` (or a scene
// root when -1) at `translation`; returns the node.
int AddMeshNode(GltfBuilder* builder, const std::string& name, nlohmann::json primitive, int parent,
                const Eigen::Vector3d& translation = Eigen::Vector3d::Zero()) {
  nlohmann::json& meshes = builder->doc()["meshes"];
  meshes.push_back({{"primitives", nlohmann::json::array({std::move(primitive)})}});
  const int node =
      builder->AddNode({{"name", name},
                        {"mesh", meshes.size() - 1},
                        {"translation", {translation.x(), translation.y(), translation.z()}}});
  if (parent >= 0) {
    builder->doc()["nodes"][parent]["children"].push_back(node);
  } else {
    builder->doc()["scenes"][0]["nodes"].push_back(node);
  }
  return node;
}

// The Tube's rig (joints at y = 0, 1, 2, radius 0.3): joint nodes 0, 1, 2, the skinned node 3.
GltfBuilder TubeRig() {
  return ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {RigidTubePrimitive(Tube())});
}

bool AnyWarningHas(const RigImport& rig, const std::string& text) {
  return std::any_of(rig.warnings.begin(), rig.warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

TEST(GltfBoneNodes, TakesAClosedMeshInsideTheSkinAsABoneOfItsJoint) {
  GltfBuilder builder = TubeRig();
  // Under joint1 through a plain transform node: the nearest joint ancestor carries it.
  const int group = builder.AddNode({{"name", "group"}, {"translation", {0.0, 0.25, 0.0}}});
  builder.doc()["nodes"][1]["children"].push_back(group);
  AddMeshNode(&builder, "tibia", BoxPrimitive(&builder, {0, 0, 0}, 0.1), group, {0, 0.25, 0});
  AddMeshNode(&builder, "femur", BoxPrimitive(&builder, {0, 0, 0}, 0.1, /*inward=*/true), 0,
              {0, 0.5, 0});
  for (const std::string& bytes : {builder.ToGltf(), builder.ToGlb()}) {
    auto rig = ReadGltf(bytes);
    ASSERT_TRUE(rig.ok()) << rig.status().ToString();
    ASSERT_EQ(rig->bone_surfaces.size(), 2u);
    for (const BoneSurface& surface : rig->bone_surfaces) {
      const bool femur = surface.name == "femur";
      EXPECT_TRUE(femur || surface.name == "tibia") << surface.name;
      // The bones start at the joints: joint0 heads bone 0, joint1 bone 1.
      EXPECT_EQ(surface.bone, femur ? 0 : 1) << surface.name;
      EXPECT_EQ(surface.mesh.num_vertices(), 8) << "seam copies welded";
      EXPECT_EQ(surface.mesh.num_triangles(), 12);
      EXPECT_TRUE(IsClosed(surface.mesh.triangles));
      EXPECT_NEAR(EnclosedVolume(surface.mesh.vertices, surface.mesh.triangles), 0.008, 1e-6)
          << surface.name << ": oriented outward";
      const Eigen::Vector3d centre = surface.mesh.vertices.colwise().mean().transpose();
      EXPECT_LT((centre - Eigen::Vector3d(0, femur ? 0.5 : 1.5, 0)).norm(), 1e-6) << surface.name;
    }
    EXPECT_FALSE(AnyWarningHas(*rig, "not a bone surface"));
  }
}

TEST(GltfBoneNodes, PlacesTheMeshInTheBindPoseWhenTheSceneIsPosed) {
  GltfBuilder builder = TubeRig();
  // The scene bends joint1 by 90 degrees about z; the inverse bind matrices keep the straight
  // tube's bind pose, so the tibia belongs at y = 1.5 on the axis, as the skin does.
  builder.doc()["nodes"][1]["rotation"] = {0.0, 0.0, std::sqrt(0.5), std::sqrt(0.5)};
  std::vector<float> inverse_bind;
  for (int j = 0; j < 3; ++j) {
    Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
    m(1, 3) = -static_cast<float>(j);
    for (int k = 0; k < 16; ++k) inverse_bind.push_back(m(k % 4, k / 4));
  }
  builder.doc()["skins"][0]["inverseBindMatrices"] =
      builder.AddAccessor(Bytes(inverse_bind), kFloat, "MAT4", 3);
  AddMeshNode(&builder, "tibia", BoxPrimitive(&builder, {0, 0, 0}, 0.1), 1, {0, 0.5, 0});
  auto rig = ReadGltf(builder.ToGlb());
  ASSERT_TRUE(rig.ok()) << rig.status().ToString();
  ASSERT_EQ(rig->bone_surfaces.size(), 1u);
  const Eigen::Vector3d centre = rig->bone_surfaces[0].mesh.vertices.colwise().mean().transpose();
  EXPECT_LT((centre - Eigen::Vector3d(0, 1.5, 0)).norm(), 1e-6) << centre.transpose();
}

TEST(GltfBoneNodes, LeavesOutPropsAndBrokenMeshesWithAWarning) {
  GltfBuilder builder = TubeRig();
  AddMeshNode(&builder, "sword", BoxPrimitive(&builder, {0.6, 0, 0}, 0.1), 2);
  AddMeshNode(&builder, "open", BoxPrimitive(&builder, {0, 0, 0}, 0.1, false, true), 0,
              {0, 0.5, 0});
  AddMeshNode(&builder, "flat", BoxPrimitive(&builder, {0, 0, 0}, 0.0), 1, {0, 0.5, 0});
  nlohmann::json lines = BoxPrimitive(&builder, {0, 0, 0}, 0.1);
  lines["mode"] = 1;
  AddMeshNode(&builder, "lines", lines, 1, {0, 0.5, 0});
  AddMeshNode(&builder, "scenery", BoxPrimitive(&builder, {0, 0.5, 0}, 0.1), -1);
  auto rig = ReadGltf(builder.ToGlb());
  ASSERT_TRUE(rig.ok()) << rig.status().ToString();
  EXPECT_TRUE(rig->bone_surfaces.empty());
  EXPECT_TRUE(AnyWarningHas(*rig,
                            "'sword' under joint 'joint2' is not a bone surface: 8 of its 8 "
                            "vertices are outside the skin"));
  EXPECT_TRUE(AnyWarningHas(*rig,
                            "'open' under joint 'joint0' is not a bone surface: it is not "
                            "closed"));
  EXPECT_TRUE(AnyWarningHas(*rig, "'flat' under joint 'joint1' is not a bone surface"));
  EXPECT_TRUE(AnyWarningHas(*rig,
                            "'lines' under joint 'joint1' is not a bone surface: primitive 0 "
                            "of mesh"));
  EXPECT_FALSE(AnyWarningHas(*rig, "scenery")) << "a node no joint carries is not a candidate";
}

TEST(GltfBoneNodes, TheWritersBoneSurfacesReadBackOnTheirBones) {
  const gltf_test::TestRig tube = Tube();
  BoneSurface femur;
  femur.name = "femur";
  femur.bone = 0;
  femur.mesh = MakeCapsule(Eigen::Vector3d(0, 0.45, 0), Eigen::Vector3d(0, 0.55, 0), 0.1, 8, 2);
  BoneSurface tibia = femur;
  tibia.name = "tibia";
  tibia.bone = 1;
  tibia.mesh = MakeCapsule(Eigen::Vector3d(0, 1.5, 0), Eigen::Vector3d(0, 1.5, 0), 0.1, 8, 2);
  for (GltfContainer container : {GltfContainer::kGltf, GltfContainer::kGlb}) {
    auto bytes = WriteGltf(tube.mesh, tube.skeleton, tube.weights, container, {femur, tibia});
    ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
    auto rig = ReadGltf(*bytes);
    ASSERT_TRUE(rig.ok()) << rig.status().ToString();
    ASSERT_EQ(rig->bone_surfaces.size(), 2u);
    for (int s = 0; s < 2; ++s) {
      const BoneSurface& written = s == 0 ? femur : tibia;
      const BoneSurface& read = rig->bone_surfaces[static_cast<std::size_t>(s)];
      EXPECT_EQ(read.name, written.name);
      EXPECT_EQ(read.bone, written.bone);
      ASSERT_EQ(read.mesh.num_vertices(), written.mesh.num_vertices());
      EXPECT_LT((read.mesh.vertices - written.mesh.vertices).cwiseAbs().maxCoeff(), 1e-6);
      EXPECT_EQ(read.mesh.triangles, written.mesh.triangles);
    }
  }
  femur.bone = 7;
  EXPECT_EQ(WriteGltf(tube.mesh, tube.skeleton, tube.weights, GltfContainer::kGlb, {femur})
                .status()
                .code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace deform
