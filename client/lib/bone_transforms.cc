#include "bone_transforms.h"

#include <Eigen/Geometry>

#include "core/geometry/bone_transform_pose.h"

namespace deform::client {
namespace {

void SetRotation(deform::v1::JointRotation* rotation, const std::string& joint,
                 const Eigen::Quaterniond& q) {
  rotation->set_joint(joint);
  rotation->set_w(q.w());
  rotation->set_x(q.x());
  rotation->set_y(q.y());
  rotation->set_z(q.z());
}

}  // namespace

BoneTransform BoneTransformFromMatrix(const std::array<double, 16>& m) {
  const Eigen::Matrix4d matrix = Eigen::Map<const Eigen::Matrix4d>(m.data());  // column-major
  const RigidTransform rigid = RigidTransformFromMatrix(matrix);
  BoneTransform result;
  result.rotation = {rigid.rotation.w(), rigid.rotation.x(), rigid.rotation.y(),
                     rigid.rotation.z()};
  result.translation = {rigid.translation.x(), rigid.translation.y(), rigid.translation.z()};
  return result;
}

bool PoseFromBoneTransforms(const deform::v1::MeshSummary& summary,
                            const std::vector<BoneTransform>& given, PoseConversion* result,
                            std::string* error) {
  std::vector<Eigen::Vector3d> joint_rest;
  joint_rest.reserve(static_cast<std::size_t>(summary.joints_size()));
  for (const auto& joint : summary.joints()) {
    const auto& p = joint.rest_position();
    joint_rest.push_back(p.size() == 3 ? Eigen::Vector3d(p[0], p[1], p[2])
                                       : Eigen::Vector3d::Zero());
  }
  std::vector<Bone> bones;
  bones.reserve(static_cast<std::size_t>(summary.bones_size()));
  for (const auto& bone : summary.bones()) {
    const auto index = [&](unsigned joint) {
      return joint < static_cast<unsigned>(summary.joints_size()) ? static_cast<int>(joint) : -1;
    };
    bones.push_back({index(bone.head_joint()), index(bone.tail_joint()), bone.parent_bone()});
  }
  std::vector<RigidTransform> transforms;
  transforms.reserve(given.size());
  for (const BoneTransform& t : given) {
    RigidTransform rigid;
    rigid.rotation = Eigen::Quaterniond(t.rotation[0], t.rotation[1], t.rotation[2], t.rotation[3]);
    rigid.translation = Eigen::Vector3d(t.translation[0], t.translation[1], t.translation[2]);
    transforms.push_back(rigid);
  }
  StatusOr<BoneTransformPose> converted = PoseFromBoneTransforms(joint_rest, bones, transforms);
  if (!converted.ok()) {
    *error = converted.status().message();
    return false;
  }
  *result = PoseConversion();
  result->sibling_disagreement_degrees = converted->sibling_disagreement_degrees;
  result->joint_gap = converted->joint_gap;
  result->root_taken_from_bone = converted->root_taken_from_bone;
  const RigidTransform& root = converted->pose.root;
  deform::v1::RootTransform* root_transform = result->pose.mutable_root();
  root_transform->mutable_translation()->set_x(root.translation.x());
  root_transform->mutable_translation()->set_y(root.translation.y());
  root_transform->mutable_translation()->set_z(root.translation.z());
  root_transform->mutable_rotation()->set_w(root.rotation.w());
  root_transform->mutable_rotation()->set_x(root.rotation.x());
  root_transform->mutable_rotation()->set_y(root.rotation.y());
  root_transform->mutable_rotation()->set_z(root.rotation.z());
  // One rotation per joint heading a bone, in the order of the bones they first head.
  std::vector<bool> written(joint_rest.size(), false);
  for (const Bone& bone : bones) {
    const auto head = static_cast<std::size_t>(bone.head_joint);
    if (written[head]) continue;
    written[head] = true;
    SetRotation(result->pose.add_rotations(), summary.joints(bone.head_joint).name(),
                converted->pose.joint_rotations[head]);
  }
  return true;
}

}  // namespace deform::client
