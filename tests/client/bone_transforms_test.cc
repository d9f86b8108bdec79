// PoseFromBoneTransforms: absolute bone transforms (what animation files hold) into the API's
// pose. Forward kinematics of the converted pose reproduces the transforms to round-off.
#include "bone_transforms.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/geometry/pose.h"
#include "core/io/phantom.h"
#include "core/io/rig_import.h"
#include "core/io/skeleton_io.h"
#include "tests/core/io/gltf_test_util.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

v1::MeshSummary SummaryOf(const Skeleton& skeleton) {
  v1::MeshSummary summary;
  for (const Joint& joint : skeleton.joints()) {
    v1::JointInfo* info = summary.add_joints();
    info->set_name(joint.name);
    for (int c = 0; c < 3; ++c) info->add_rest_position(joint.rest_position[c]);
  }
  for (const Bone& bone : skeleton.bones()) {
    v1::BoneInfo* info = summary.add_bones();
    info->set_head_joint(bone.head_joint);
    info->set_tail_joint(bone.tail_joint);
    info->set_parent_bone(bone.parent_bone);
  }
  return summary;
}

Pose RandomPose(const Skeleton& skeleton, std::mt19937* random) {
  std::normal_distribution<double> gaussian;
  Pose pose = Pose::Rest(skeleton);
  for (auto& rotation : pose.joint_rotations) {
    rotation = Eigen::Quaterniond(1 + 0.5 * gaussian(*random), 0.4 * gaussian(*random),
                                  0.4 * gaussian(*random), 0.4 * gaussian(*random))
                   .normalized();
  }
  pose.root.rotation =
      Eigen::Quaterniond(gaussian(*random), gaussian(*random), gaussian(*random), gaussian(*random))
          .normalized();
  pose.root.translation = Eigen::Vector3d(10 * gaussian(*random), gaussian(*random), 3);
  return pose;
}

// The API's pose back into the core's (rotations by joint name, the root).
Pose CorePose(const Skeleton& skeleton, const v1::PoseUpdate& update) {
  Pose pose = Pose::Rest(skeleton);
  for (const v1::JointRotation& r : update.rotations()) {
    const int joint = *skeleton.FindJoint(r.joint());
    pose.joint_rotations[joint] = Eigen::Quaterniond(r.w(), r.x(), r.y(), r.z()).normalized();
  }
  const auto& root = update.root();
  pose.root.rotation = Eigen::Quaterniond(root.rotation().w(), root.rotation().x(),
                                          root.rotation().y(), root.rotation().z())
                           .normalized();
  pose.root.translation =
      Eigen::Vector3d(root.translation().x(), root.translation().y(), root.translation().z());
  return pose;
}

void ExpectRoundTrip(const Skeleton& skeleton) {
  const v1::MeshSummary summary = SummaryOf(skeleton);
  std::mt19937 random(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pose = RandomPose(skeleton, &random);
    std::vector<RigidTransform> expected;
    ForwardKinematics(skeleton, pose, &expected);
    std::vector<client::BoneTransform> given;
    for (const RigidTransform& t : expected) {
      given.push_back({{t.rotation.w(), t.rotation.x(), t.rotation.y(), t.rotation.z()},
                       {t.translation.x(), t.translation.y(), t.translation.z()}});
    }
    client::PoseConversion conversion;
    std::string error;
    ASSERT_TRUE(client::PoseFromBoneTransforms(summary, given, &conversion, &error)) << error;
    EXPECT_LT(conversion.sibling_disagreement_degrees, 1e-9);
    EXPECT_LT(conversion.joint_gap, 1e-9);
    std::vector<RigidTransform> again;
    ForwardKinematics(skeleton, CorePose(skeleton, conversion.pose), &again);
    for (std::size_t k = 0; k < expected.size(); ++k) {
      EXPECT_LT(expected[k].rotation.angularDistance(again[k].rotation), 1e-12) << "bone " << k;
      EXPECT_LT((expected[k].translation - again[k].translation).norm(), 1e-9) << "bone " << k;
    }
  }
}

TEST(PoseFromBoneTransforms, ReproducesThePhantomsBoneTransforms) {
  auto phantom = MakeKneePhantom(300);
  ASSERT_TRUE(phantom.ok());
  ExpectRoundTrip(phantom->skeleton);
}

TEST(PoseFromBoneTransforms, ReproducesABranchingBodyRig) {
  DEFORM_REQUIRE_SHARED_FILE(path, "body/body.tgf");
  auto skeleton = ReadSkeletonFile(path);
  ASSERT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  ExpectRoundTrip(*skeleton);
}

TEST(PoseFromBoneTransforms, ReportsTransformsThatAreNoPoseOfTheSkeleton) {
  auto phantom = MakeKneePhantom(300);
  ASSERT_TRUE(phantom.ok());
  const v1::MeshSummary summary = SummaryOf(phantom->skeleton);
  std::vector<client::BoneTransform> given(phantom->skeleton.num_bones());
  given.front().translation = {0, 0, 0.25};   // the thigh moves (not a static root)
  given.back().translation = {0.5, 0, 0.25};  // and the shin leaves the knee
  client::PoseConversion conversion;
  std::string error;
  ASSERT_TRUE(client::PoseFromBoneTransforms(summary, given, &conversion, &error));
  EXPECT_NEAR(conversion.joint_gap, 0.5, 1e-12);
  given.pop_back();
  EXPECT_FALSE(client::PoseFromBoneTransforms(summary, given, &conversion, &error));
  EXPECT_NE(error.find("bone transforms"), std::string::npos) << error;
}

using gltf_test::NodeMatrix;

TEST(PoseFromBoneTransforms, TakesRootMotionFromTheHipUnderAStaticWeightlessTopJoint) {
  // glTF nodes root -> hip -> knee -> ankle, one unit apart along +Y; the tube (moved up one unit)
  // blends between hip and knee; the top joint "root" carries no weight and stays at rest.
  const gltf_test::TestRig tube = gltf_test::Tube();
  gltf_test::PrimitiveData data;
  for (int v = 0; v < tube.mesh.num_vertices(); ++v) {
    const double y = tube.mesh.vertices(v, 1);
    data.positions.insert(data.positions.end(),
                          {static_cast<float>(tube.mesh.vertices(v, 0)), static_cast<float>(y + 1),
                           static_cast<float>(tube.mesh.vertices(v, 2))});
    const float w = static_cast<float>(gltf_test::LowerBoneWeight(y));
    data.joints.insert(data.joints.end(), {1, 2, 0, 0});
    data.weights.insert(data.weights.end(), {w, 1 - w, 0, 0});
  }
  for (Eigen::Index t = 0; t < tube.mesh.triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c)
      data.indices.push_back(static_cast<std::uint32_t>(tube.mesh.triangles(t, c)));
  }
  gltf_test::GltfBuilder builder =
      gltf_test::ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 3, 0}}, {data});
  const std::vector<std::string> names = {"root", "hip", "knee", "ankle"};
  for (std::size_t j = 0; j < names.size(); ++j) builder.doc()["nodes"][j]["name"] = names[j];
  auto rig = ReadGltf(builder.ToGlb());
  ASSERT_TRUE(rig.ok()) << rig.status().ToString();

  // The animated frame: the hip translated and turned, the knee bent; the root at rest. The file's
  // own skinning (glTF: joint matrix = posed world * inverse bind), written here.
  const std::vector<Eigen::Vector3d> rest_local = {{0, 0, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
  std::vector<Eigen::Vector3d> local = rest_local;
  std::vector<Eigen::Quaterniond> turn(4, Eigen::Quaterniond::Identity());
  local[1] = {0.3, 1.2, -0.4};
  turn[1] = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 0.5).normalized()));
  turn[2] = Eigen::Quaterniond(Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitX()));
  std::vector<Eigen::Matrix4d> rest_world(4), posed_world(4), joint_matrix(4);
  for (std::size_t j = 0; j < 4; ++j) {
    const Eigen::Matrix4d parent_rest = j == 0 ? Eigen::Matrix4d::Identity() : rest_world[j - 1];
    const Eigen::Matrix4d parent_posed = j == 0 ? Eigen::Matrix4d::Identity() : posed_world[j - 1];
    rest_world[j] = parent_rest * NodeMatrix(rest_local[j], Eigen::Quaterniond::Identity());
    posed_world[j] = parent_posed * NodeMatrix(local[j], turn[j]);
    joint_matrix[j] = posed_world[j] * rest_world[j].inverse();
  }
  const int n = data.vertex_count();
  const Positions reference = gltf_test::SkinAsGltf(data, joint_matrix);

  // Bone transforms as an engine holds them: each bone's head joint's joint matrix.
  std::vector<client::BoneTransform> given;
  for (const Bone& bone : rig->skeleton.bones()) {
    const std::string& head = rig->skeleton.joint(bone.head_joint).name;
    const auto node = std::find(names.begin(), names.end(), head) - names.begin();
    std::array<double, 16> m;
    for (int k = 0; k < 16; ++k) m[k] = joint_matrix[node](k % 4, k / 4);
    given.push_back(client::BoneTransformFromMatrix(m));
  }
  client::PoseConversion conversion;
  std::string error;
  ASSERT_TRUE(client::PoseFromBoneTransforms(SummaryOf(rig->skeleton), given, &conversion, &error))
      << error;
  EXPECT_EQ(conversion.root_taken_from_bone, 1) << "the hip's bone carries the motion";
  std::vector<RigidTransform> transforms;
  ForwardKinematics(rig->skeleton, CorePose(rig->skeleton, conversion.pose), &transforms);
  const Positions& rest = rig->mesh.vertices;
  const double diagonal = (rest.colwise().maxCoeff() - rest.colwise().minCoeff()).norm();
  double worst = 0;
  for (int v = 0; v < n; ++v) {
    const int m = rig->file_vertex_to_mesh[static_cast<std::size_t>(v)];
    Eigen::Vector3d lbs = Eigen::Vector3d::Zero();
    for (int e = rig->weights.offsets[m]; e < rig->weights.offsets[m + 1]; ++e) {
      const RigidTransform& t = transforms[static_cast<std::size_t>(rig->weights.bones[e])];
      lbs += rig->weights.weights[e] * (t.rotation * rest.row(m).transpose() + t.translation);
    }
    worst = std::max(worst, (lbs - reference.row(v).transpose()).norm());
  }
  EXPECT_LT(worst, 1e-6 * diagonal) << "lbs against the file's own skinning";
}

TEST(BoneTransformFromMatrix, ReadsAColumnMajorRigidMatrix) {
  // 90 degrees about +Z, then translation (1, 2, 3).
  const std::array<double, 16> m = {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 1, 2, 3, 1};
  const client::BoneTransform t = client::BoneTransformFromMatrix(m);
  const Eigen::Quaterniond q(t.rotation[0], t.rotation[1], t.rotation[2], t.rotation[3]);
  EXPECT_LT((q * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_EQ(t.translation, (std::array<double, 3>{1, 2, 3}));
}

}  // namespace
}  // namespace deform
