#include "gltf_rig_skeleton.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

namespace deform::gltf_internal {
namespace {

// Skin joints ordered so that every parent precedes its children. Precondition: a forest.
std::vector<int> ParentsFirst(const std::vector<SkinJoint>& joints) {
  const int n = static_cast<int>(joints.size());
  std::vector<std::vector<int>> children(joints.size());
  std::vector<int> order;
  for (int j = 0; j < n; ++j) {
    if (joints[static_cast<std::size_t>(j)].parent < 0) {
      order.push_back(j);
    } else {
      children[static_cast<std::size_t>(joints[static_cast<std::size_t>(j)].parent)].push_back(j);
    }
  }
  for (std::size_t q = 0; q < order.size(); ++q) {
    for (int c : children[static_cast<std::size_t>(order[q])]) order.push_back(c);
  }
  return order;
}

std::string UniqueName(const std::string& wanted, std::set<std::string>* taken) {
  std::string name = wanted;
  for (int k = 2; taken->count(name) != 0; ++k) name = wanted + "_" + std::to_string(k);
  taken->insert(name);
  return name;
}

}  // namespace

StatusOr<RigSkeleton> BuildRigSkeleton(const std::vector<SkinJoint>& joints,
                                       double merge_tolerance) {
  const std::vector<int> order = ParentsFirst(joints);
  if (order.size() != joints.size()) {
    return Status::InvalidArgument("the skin's joint hierarchy is not a forest");
  }
  // The skin joint each joint is merged into (itself when kept), and each kept joint's skeleton
  // joint.
  std::vector<int> kept_as(joints.size(), -1);
  std::vector<int> skeleton_joint(joints.size(), -1);
  std::vector<Joint> skeleton_joints;
  std::vector<std::pair<int, int>> bones;
  std::vector<int> skeleton_parent;  // per skeleton joint
  std::vector<char> skeleton_weighted;
  std::set<std::string> names;
  for (const SkinJoint& joint : joints) names.insert(joint.name);
  for (int j : order) {
    const SkinJoint& joint = joints[static_cast<std::size_t>(j)];
    const int parent = joint.parent < 0 ? -1 : kept_as[static_cast<std::size_t>(joint.parent)];
    if (parent >= 0 &&
        (joint.position - joints[static_cast<std::size_t>(parent)].position).norm() <=
            merge_tolerance) {
      kept_as[static_cast<std::size_t>(j)] = parent;
      if (joint.weight_total > 0) {
        skeleton_weighted[static_cast<std::size_t>(
            skeleton_joint[static_cast<std::size_t>(parent)])] = 1;
      }
      continue;
    }
    kept_as[static_cast<std::size_t>(j)] = j;
    skeleton_joint[static_cast<std::size_t>(j)] = static_cast<int>(skeleton_joints.size());
    skeleton_joints.push_back({joint.name, joint.position, {}});
    skeleton_parent.push_back(parent < 0 ? -1 : skeleton_joint[static_cast<std::size_t>(parent)]);
    skeleton_weighted.push_back(joint.weight_total > 0 ? 1 : 0);
    if (parent >= 0) {
      bones.emplace_back(skeleton_joint[static_cast<std::size_t>(parent)],
                         skeleton_joint[static_cast<std::size_t>(j)]);
    }
  }
  // End bones for weighted joints that head no bone.
  const int num_kept = static_cast<int>(skeleton_joints.size());
  std::vector<char> heads_bone(static_cast<std::size_t>(num_kept), 0);
  for (const auto& bone : bones) heads_bone[static_cast<std::size_t>(bone.first)] = 1;
  for (int s = 0; s < num_kept; ++s) {
    if (heads_bone[static_cast<std::size_t>(s)] ||
        !skeleton_weighted[static_cast<std::size_t>(s)]) {
      continue;
    }
    const Eigen::Vector3d head = skeleton_joints[static_cast<std::size_t>(s)].rest_position;
    Eigen::Vector3d tail;
    const int parent = skeleton_parent[static_cast<std::size_t>(s)];
    if (parent >= 0) {
      tail = head + 0.5 * (head - skeleton_joints[static_cast<std::size_t>(parent)].rest_position);
    } else {
      // A lone joint: toward the centroid of its weighted vertices (with those of the skin
      // joints merged into it).
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
      double total = 0;
      for (std::size_t j = 0; j < joints.size(); ++j) {
        if (skeleton_joint[static_cast<std::size_t>(kept_as[j])] == s) {
          sum += joints[j].weighted_position_sum;
          outer += joints[j].weighted_outer_sum;
          total += joints[j].weight_total;
        }
      }
      const Eigen::Vector3d centroid = sum / total;
      if ((centroid - head).norm() > merge_tolerance) {
        tail = head + 2.0 * (centroid - head);
      } else {
        const Eigen::Matrix3d covariance = outer / total - centroid * centroid.transpose();
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal(covariance);
        const double spread = std::sqrt(std::max(principal.eigenvalues()(2), 0.0));
        if (!(spread > merge_tolerance)) {
          return Status::InvalidArgument(
              "joint '" + skeleton_joints[static_cast<std::size_t>(s)].name +
              "' has no parent or child joint and its vertices neither lie to one side nor "
              "spread along a direction: no direction for its bone");
        }
        Eigen::Vector3d axis = principal.eigenvectors().col(2);
        Eigen::Index largest;
        axis.cwiseAbs().maxCoeff(&largest);
        if (axis(largest) < 0) axis = -axis;  // a fixed sign: the largest component positive
        tail = head + 2.0 * spread * axis;
      }
    }
    const std::string end_name =
        UniqueName(skeleton_joints[static_cast<std::size_t>(s)].name + "_end", &names);
    bones.emplace_back(s, static_cast<int>(skeleton_joints.size()));
    skeleton_joints.push_back({end_name, tail, {}});
  }
  RigSkeleton rig;
  DEFORM_ASSIGN_OR_RETURN(rig.skeleton, Skeleton::Create(std::move(skeleton_joints), bones));
  std::vector<std::vector<int>> bones_of_head(static_cast<std::size_t>(rig.skeleton.num_joints()));
  for (int b = 0; b < rig.skeleton.num_bones(); ++b) {
    bones_of_head[static_cast<std::size_t>(rig.skeleton.bone(b).head_joint)].push_back(b);
  }
  rig.bones_of_joint.resize(joints.size());
  for (std::size_t j = 0; j < joints.size(); ++j) {
    rig.bones_of_joint[j] = bones_of_head[static_cast<std::size_t>(
        skeleton_joint[static_cast<std::size_t>(kept_as[j])])];
  }
  return rig;
}

int NearestBone(const Skeleton& skeleton, const std::vector<int>& candidates,
                const Eigen::Vector3d& point) {
  int best = candidates.front();
  double best_distance = std::numeric_limits<double>::infinity();
  for (int b : candidates) {
    const Eigen::Vector3d head = skeleton.joint(skeleton.bone(b).head_joint).rest_position;
    const Eigen::Vector3d axis = skeleton.joint(skeleton.bone(b).tail_joint).rest_position - head;
    const double t = std::clamp((point - head).dot(axis) / axis.squaredNorm(), 0.0, 1.0);
    const double distance = (point - (head + t * axis)).squaredNorm();
    if (distance < best_distance) {
      best_distance = distance;
      best = b;
    }
  }
  return best;
}

}  // namespace deform::gltf_internal
