// Internal to the glTF import: turning a skin's joints (points in a hierarchy) into the core's
// Skeleton (bones with a head and a tail of non-zero length), and telling which bones a glTF
// joint's weight may go to.
//
//   - A bone per (parent joint -> child joint) pair, the parent being the nearest ancestor node
//     that is also a joint of the skin.
//   - A joint within `merge_tolerance` of its (merged) parent joint is merged into it: it becomes
//     the same skeleton joint, its children hang from the parent, its weights go to the parent's
//     bones. (Twist and helper joints often sit exactly on their parent.)
//   - A joint that heads no bone but has weighted vertices gets an end joint "<name>_end": along
//     the parent->joint direction, half the parent bone's length; a joint without a parent (a
//     one-joint skin) instead points at the weighted centroid of its vertices, twice as far (and
//     when that centroid is the joint itself, along the vertices' principal direction, two
//     standard deviations long).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/skeleton.h"

namespace deform::gltf_internal {

struct SkinJoint {
  std::string name;          // unique, non-empty
  Eigen::Vector3d position;  // bind-pose position in the mesh's space
  int parent = -1;           // index into the skin's joints, or -1; parents form a forest
  // Its vertices: the sum of their weights on it, and of weight * position (for a weighted joint
  // without parent or child, whose bone points at their centroid).
  double weight_total = 0;
  Eigen::Vector3d weighted_position_sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d weighted_outer_sum = Eigen::Matrix3d::Zero();  // sum of weight * x * x^T
};

struct RigSkeleton {
  Skeleton skeleton;
  // Per skin joint: the bones its weight may go to (the bones that start at its skeleton joint);
  // empty only for an unweighted joint that heads no bone.
  std::vector<std::vector<int>> bones_of_joint;
};

// INVALID_ARGUMENT when no usable skeleton results (no bones, or a lone joint with nothing to
// point at), naming the joint.
StatusOr<RigSkeleton> BuildRigSkeleton(const std::vector<SkinJoint>& joints,
                                       double merge_tolerance);

// Of `candidates` (bone indices), the bone nearest to `point` (distance to the bone's segment);
// the first on ties. Precondition: candidates is not empty.
int NearestBone(const Skeleton& skeleton, const std::vector<int>& candidates,
                const Eigen::Vector3d& point);

}  // namespace deform::gltf_internal
