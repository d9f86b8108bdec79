#include "core/geometry/bone_transform_pose.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <string>

namespace deform {
namespace {

// A child bone's head farther than this (relative to the coordinates' size) from where its root
// bone's transform takes it means the motion is carried below the root (float round-off of an
// exported pose stays far below).
constexpr double kRootMotionTolerance = 1e-7;

Status CheckSkeleton(const std::vector<Eigen::Vector3d>& joint_rest, const std::vector<Bone>& bones,
                     std::size_t transforms) {
  if (transforms != bones.size()) {
    return Status::InvalidArgument("got " + std::to_string(transforms) +
                                   " bone transforms for a skeleton of " +
                                   std::to_string(bones.size()) + " bones");
  }
  const int joints = static_cast<int>(joint_rest.size());
  const int bone_count = static_cast<int>(bones.size());
  for (const Bone& bone : bones) {
    if (bone.head_joint < 0 || bone.head_joint >= joints || bone.tail_joint < 0 ||
        bone.tail_joint >= joints || bone.parent_bone >= bone_count || bone.parent_bone < -1) {
      return Status::InvalidArgument(
          "the skeleton's bones refer to joints or bones it does not have");
    }
  }
  return Status::Ok();
}

// The root transform: every root bone's head turns about itself, so the root must carry each root
// head o_k to B_k(o_k). One root head (a tree, as rigs are): the first root bone's own transform.
// Several heads spanning a plane (a skeleton read as a forest): the best rigid fit of the heads
// (Kabsch), exact for a pose of this skeleton.
RigidTransform PlaceRoot(const std::vector<Eigen::Vector3d>& joint_rest,
                         const std::vector<Bone>& bones,
                         const std::vector<RigidTransform>& transforms, int first_root) {
  RigidTransform placement = transforms[static_cast<std::size_t>(first_root)];
  std::vector<Eigen::Vector3d> rest, posed;
  for (std::size_t k = 0; k < bones.size(); ++k) {
    if (bones[k].parent_bone >= 0) continue;
    const Eigen::Vector3d& head = joint_rest[static_cast<std::size_t>(bones[k].head_joint)];
    rest.push_back(head);
    posed.push_back(transforms[k].Apply(head));
  }
  Eigen::Vector3d rest_mean = Eigen::Vector3d::Zero(), posed_mean = Eigen::Vector3d::Zero();
  for (std::size_t h = 0; h < rest.size(); ++h) {
    rest_mean += rest[h] / static_cast<double>(rest.size());
    posed_mean += posed[h] / static_cast<double>(rest.size());
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
std::vector<RigidTransform> RootFromMovingChild(const std::vector<Eigen::Vector3d>& joint_rest,
                                                const std::vector<Bone>& bones,
                                                const std::vector<RigidTransform>& transforms,
                                                int* taken_from) {
  std::vector<RigidTransform> used = transforms;
  *taken_from = -1;
  for (std::size_t r = 0; r < bones.size(); ++r) {
    if (bones[r].parent_bone >= 0) continue;
    const RigidTransform& root = transforms[r];
    const bool at_rest =
        root.rotation.angularDistance(Eigen::Quaterniond::Identity()) <= kRootMotionTolerance &&
        root.translation.norm() <= kRootMotionTolerance;
    if (!at_rest) continue;
    for (std::size_t c = 0; c < bones.size(); ++c) {
      if (bones[c].parent_bone != static_cast<int>(r)) continue;
      const Eigen::Vector3d& head = joint_rest[static_cast<std::size_t>(bones[c].head_joint)];
      const Eigen::Vector3d by_root = root.Apply(head);
      const Eigen::Vector3d by_child = transforms[c].Apply(head);
      const double scale = 1 + head.norm() + transforms[c].translation.norm();
      if ((by_root - by_child).norm() > kRootMotionTolerance * scale) {
        used[r] = transforms[c];
        if (*taken_from < 0) *taken_from = static_cast<int>(c);
      }
      break;  // the first child bone decides
    }
  }
  return used;
}

}  // namespace

RigidTransform RigidTransformFromMatrix(const Eigen::Matrix4d& matrix) {
  const Eigen::Matrix3d rotation = matrix.block<3, 3>(0, 0);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d orthonormal = svd.matrixU() * svd.matrixV().transpose();
  if (orthonormal.determinant() < 0) orthonormal = -orthonormal;
  RigidTransform result;
  result.rotation = Eigen::Quaterniond(orthonormal);
  result.translation = matrix.block<3, 1>(0, 3);
  return result;
}

StatusOr<BoneTransformPose> PoseFromBoneTransforms(const std::vector<Eigen::Vector3d>& joint_rest,
                                                   const std::vector<Bone>& bones,
                                                   const std::vector<RigidTransform>& given) {
  DEFORM_RETURN_IF_ERROR(CheckSkeleton(joint_rest, bones, given.size()));
  std::vector<RigidTransform> normalized = given;
  for (RigidTransform& t : normalized) t.rotation.normalize();
  BoneTransformPose result;
  const std::vector<RigidTransform> transforms =
      RootFromMovingChild(joint_rest, bones, normalized, &result.root_taken_from_bone);
  const int bone_count = static_cast<int>(bones.size());
  int root_bone = -1;
  for (int k = 0; k < bone_count && root_bone < 0; ++k) {
    if (bones[static_cast<std::size_t>(k)].parent_bone < 0) root_bone = k;
  }
  if (root_bone < 0) return Status::InvalidArgument("the skeleton has no root bone");
  result.pose.root = PlaceRoot(joint_rest, bones, transforms, root_bone);
  result.pose.joint_rotations.assign(joint_rest.size(), Eigen::Quaterniond::Identity());
  result.heads_bone.assign(joint_rest.size(), false);
  std::vector<int> first_bone_of_joint(joint_rest.size(), -1);
  for (int k = 0; k < bone_count; ++k) {
    const Bone& bone = bones[static_cast<std::size_t>(k)];
    const RigidTransform& t = transforms[static_cast<std::size_t>(k)];
    const int parent = bone.parent_bone;
    const RigidTransform& carrier =
        parent >= 0 ? transforms[static_cast<std::size_t>(parent)] : result.pose.root;
    const auto head = static_cast<std::size_t>(bone.head_joint);
    if (first_bone_of_joint[head] < 0) {
      first_bone_of_joint[head] = k;
      result.heads_bone[head] = true;
      result.pose.joint_rotations[head] = (carrier.rotation.conjugate() * t.rotation).normalized();
    } else {
      const Eigen::Quaterniond& sibling =
          transforms[static_cast<std::size_t>(first_bone_of_joint[head])].rotation;
      const double degrees = sibling.angularDistance(t.rotation) * 180.0 / M_PI;
      result.sibling_disagreement_degrees = std::max(result.sibling_disagreement_degrees, degrees);
    }
    // Where the head goes with this bone, and where its parent (or the root) takes it.
    const Eigen::Vector3d& head_rest = joint_rest[head];
    result.joint_gap =
        std::max(result.joint_gap, (t.Apply(head_rest) - carrier.Apply(head_rest)).norm());
  }
  return result;
}

}  // namespace deform
