#include "bone_transforms.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace deform::client {
namespace {

Eigen::Quaterniond ToQuaternion(const std::array<double, 4>& q) {
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
}

Eigen::Vector3d ToVector(const std::array<double, 3>& t) { return {t[0], t[1], t[2]}; }

// A child bone's head farther than this (relative to the coordinates' size) from where its root
// bone's transform takes it means the motion is carried below the root (float round-off of an
// exported pose stays far below).
constexpr double kRootMotionTolerance = 1e-7;

Eigen::Vector3d RestPosition(const deform::v1::MeshSummary& summary, int joint) {
  const auto& p = summary.joints(joint).rest_position();
  return p.size() == 3 ? Eigen::Vector3d(p[0], p[1], p[2]) : Eigen::Vector3d::Zero();
}

void SetRotation(deform::v1::JointRotation* rotation, const std::string& joint,
                 const Eigen::Quaterniond& q) {
  rotation->set_joint(joint);
  rotation->set_w(q.w());
  rotation->set_x(q.x());
  rotation->set_y(q.y());
  rotation->set_z(q.z());
}

bool CheckSkeleton(const deform::v1::MeshSummary& summary, std::size_t transforms,
                   std::string* error) {
  if (transforms != static_cast<std::size_t>(summary.bones_size())) {
    *error = "got " + std::to_string(transforms) + " bone transforms for a skeleton of " +
             std::to_string(summary.bones_size()) + " bones";
    return false;
  }
  for (const auto& bone : summary.bones()) {
    if (bone.head_joint() >= static_cast<unsigned>(summary.joints_size()) ||
        bone.tail_joint() >= static_cast<unsigned>(summary.joints_size()) ||
        bone.parent_bone() >= summary.bones_size() || bone.parent_bone() < -1) {
      *error = "the mesh summary's skeleton refers to joints or bones it does not have";
      return false;
    }
  }
  return true;
}

struct RootPlacement {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
};

// The root transform: every root bone's head turns about itself, so the root must carry each root
// head o_k to B_k(o_k). One root head (a tree, as rigs are): the first root bone's own transform.
// Several heads spanning a plane (a skeleton read as a forest): the best rigid fit of the heads
// (Kabsch), exact for a pose of this skeleton.
RootPlacement PlaceRoot(const deform::v1::MeshSummary& summary,
                        const std::vector<BoneTransform>& bones, int first_root) {
  RootPlacement placement;
  placement.rotation = ToQuaternion(bones[first_root].rotation);
  placement.translation = ToVector(bones[first_root].translation);
  std::vector<Eigen::Vector3d> rest, posed;
  for (int k = 0; k < summary.bones_size(); ++k) {
    if (summary.bones(k).parent_bone() >= 0) continue;
    const Eigen::Vector3d head =
        RestPosition(summary, static_cast<int>(summary.bones(k).head_joint()));
    rest.push_back(head);
    posed.push_back(ToQuaternion(bones[k].rotation) * head + ToVector(bones[k].translation));
  }
  Eigen::Vector3d rest_mean = Eigen::Vector3d::Zero(), posed_mean = Eigen::Vector3d::Zero();
  for (std::size_t h = 0; h < rest.size(); ++h) {
    rest_mean += rest[h] / rest.size();
    posed_mean += posed[h] / rest.size();
  }
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t h = 0; h < rest.size(); ++h) {
    covariance += (posed[h] - posed_mean) * (rest[h] - rest_mean).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d spread = svd.singularValues();
  if (!(spread[1] > 1e-9 * (spread[0] + 1e-300))) return placement;  // the heads span no plane
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  placement.rotation = Eigen::Quaterniond(svd.matrixU() * d * svd.matrixV().transpose());
  placement.translation = posed_mean - placement.rotation * rest_mean;
  return placement;
}

// A root bone at rest (identity transform) whose first child bone's head is not where the child's
// transform takes it (a static, weightless top joint above a hip that carries the motion) takes the
// transform of its first child bone: the child's heads then sit on its tail and the pose is exact
// for every bone but that root bone (which a static top joint's skin does not follow). Returns the
// bones used, and the child taken (or -1) in `taken_from`.
std::vector<BoneTransform> RootFromMovingChild(const deform::v1::MeshSummary& summary,
                                               const std::vector<BoneTransform>& bones,
                                               int* taken_from) {
  std::vector<BoneTransform> used = bones;
  *taken_from = -1;
  for (int r = 0; r < summary.bones_size(); ++r) {
    if (summary.bones(r).parent_bone() >= 0) continue;
    const bool at_rest =
        ToQuaternion(bones[r].rotation).angularDistance(Eigen::Quaterniond::Identity()) <=
            kRootMotionTolerance &&
        ToVector(bones[r].translation).norm() <= kRootMotionTolerance;
    if (!at_rest) continue;
    for (int c = 0; c < summary.bones_size(); ++c) {
      if (summary.bones(c).parent_bone() != r) continue;
      const Eigen::Vector3d head =
          RestPosition(summary, static_cast<int>(summary.bones(c).head_joint()));
      const Eigen::Vector3d by_root =
          ToQuaternion(bones[r].rotation) * head + ToVector(bones[r].translation);
      const Eigen::Vector3d by_child =
          ToQuaternion(bones[c].rotation) * head + ToVector(bones[c].translation);
      const double scale = 1 + head.norm() + ToVector(bones[c].translation).norm();
      if ((by_root - by_child).norm() > kRootMotionTolerance * scale) {
        used[r] = bones[c];
        if (*taken_from < 0) *taken_from = c;
      }
      break;  // the first child bone decides
    }
  }
  return used;
}

}  // namespace

BoneTransform BoneTransformFromMatrix(const std::array<double, 16>& m) {
  Eigen::Matrix3d rotation;
  rotation << m[0], m[4], m[8], m[1], m[5], m[9], m[2], m[6], m[10];
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d orthonormal = svd.matrixU() * svd.matrixV().transpose();
  if (orthonormal.determinant() < 0) orthonormal = -orthonormal;
  const Eigen::Quaterniond q(orthonormal);
  BoneTransform result;
  result.rotation = {q.w(), q.x(), q.y(), q.z()};
  result.translation = {m[12], m[13], m[14]};
  return result;
}

bool PoseFromBoneTransforms(const deform::v1::MeshSummary& summary,
                            const std::vector<BoneTransform>& given, PoseConversion* result,
                            std::string* error) {
  if (!CheckSkeleton(summary, given.size(), error)) return false;
  *result = PoseConversion();
  const std::vector<BoneTransform> bones =
      RootFromMovingChild(summary, given, &result->root_taken_from_bone);
  const int bone_count = summary.bones_size();
  int root_bone = -1;
  for (int k = 0; k < bone_count && root_bone < 0; ++k) {
    if (summary.bones(k).parent_bone() < 0) root_bone = k;
  }
  if (root_bone < 0) {
    *error = "the mesh summary's skeleton has no root bone";
    return false;
  }
  const RootPlacement placement = PlaceRoot(summary, bones, root_bone);
  const Eigen::Quaterniond root = placement.rotation;
  deform::v1::RootTransform* root_transform = result->pose.mutable_root();
  root_transform->mutable_translation()->set_x(placement.translation.x());
  root_transform->mutable_translation()->set_y(placement.translation.y());
  root_transform->mutable_translation()->set_z(placement.translation.z());
  root_transform->mutable_rotation()->set_w(root.w());
  root_transform->mutable_rotation()->set_x(root.x());
  root_transform->mutable_rotation()->set_y(root.y());
  root_transform->mutable_rotation()->set_z(root.z());

  std::vector<int> first_bone_of_joint(summary.joints_size(), -1);
  for (int k = 0; k < bone_count; ++k) {
    const auto& bone = summary.bones(k);
    const Eigen::Quaterniond rotation = ToQuaternion(bones[k].rotation);
    const int parent = bone.parent_bone();
    const Eigen::Quaterniond parent_rotation =
        parent >= 0 ? ToQuaternion(bones[parent].rotation) : root;
    const Eigen::Quaterniond local = parent_rotation.conjugate() * rotation;
    const int head = static_cast<int>(bone.head_joint());
    if (first_bone_of_joint[head] < 0) {
      first_bone_of_joint[head] = k;
      SetRotation(result->pose.add_rotations(), summary.joints(head).name(), local);
    } else {
      const Eigen::Quaterniond sibling = ToQuaternion(bones[first_bone_of_joint[head]].rotation);
      const double degrees = sibling.angularDistance(rotation) * 180.0 / M_PI;
      result->sibling_disagreement_degrees =
          std::max(result->sibling_disagreement_degrees, degrees);
    }
    // Where the head goes with this bone, and where its parent (or the root) takes it.
    const Eigen::Vector3d head_rest = RestPosition(summary, head);
    const Eigen::Vector3d posed = rotation * head_rest + ToVector(bones[k].translation);
    const Eigen::Vector3d by_parent =
        parent >= 0 ? Eigen::Vector3d(ToQuaternion(bones[parent].rotation) * head_rest +
                                      ToVector(bones[parent].translation))
                    : Eigen::Vector3d(root * head_rest + placement.translation);
    result->joint_gap = std::max(result->joint_gap, (posed - by_parent).norm());
  }
  return true;
}

}  // namespace deform::client
