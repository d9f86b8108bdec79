#include "core/geometry/skeleton.h"

#include <cmath>
#include <string>
#include <unordered_set>
#include <utility>

#include "core/base/text.h"

namespace deform {
namespace {

// A joint's degrees of freedom: usable, distinct names, non-zero finite axes (normalized here)
// and valid ranges.
Status CheckDegreesOfFreedom(Joint* joint) {
  std::unordered_set<std::string> names;
  for (DegreeOfFreedom& dof : joint->dofs) {
    if (dof.name.empty() || dof.name == "x" || dof.name == "y" || dof.name == "z") {
      return Status::InvalidArgument("joint '" + joint->name +
                                     "' has a degree of freedom without a usable name");
    }
    if (!names.insert(dof.name).second) {
      return Status::InvalidArgument("joint '" + joint->name + "' names degree of freedom '" +
                                     dof.name + "' twice");
    }
    const double length = dof.axis.norm();
    if (!std::isfinite(length) || length < 1e-12) {
      return Status::InvalidArgument("degree of freedom '" + joint->name + ":" + dof.name +
                                     "' has a zero or non-finite axis");
    }
    dof.axis /= length;
    if (!std::isfinite(dof.min_degrees) || !std::isfinite(dof.max_degrees) ||
        dof.min_degrees > dof.max_degrees) {
      return Status::InvalidArgument("degree of freedom '" + joint->name + ":" + dof.name +
                                     "' has an invalid range");
    }
  }
  return Status::Ok();
}

// Joint names unique and non-empty, finite positions, valid degrees of freedom.
Status CheckJoints(std::vector<Joint>* joints) {
  std::unordered_set<std::string> names;
  for (std::size_t j = 0; j < joints->size(); ++j) {
    Joint& joint = (*joints)[j];
    if (joint.name.empty()) {
      return Status::InvalidArgument("joint " + std::to_string(j) + " has no name");
    }
    if (!names.insert(joint.name).second) {
      return Status::InvalidArgument("joint name '" + joint.name + "' is used twice");
    }
    if (!joint.rest_position.allFinite()) {
      return Status::InvalidArgument("joint '" + joint.name + "' has a non-finite position");
    }
    DEFORM_RETURN_IF_ERROR(CheckDegreesOfFreedom(&joint));
  }
  return Status::Ok();
}

// A bone's joints exist, it has a length and its tail ends no other bone.
Status CheckBone(const std::vector<Joint>& joints, const std::vector<int>& incoming_bone, int k,
                 int head, int tail) {
  const int nj = static_cast<int>(joints.size());
  if (head < 0 || head >= nj || tail < 0 || tail >= nj) {
    return Status::InvalidArgument("bone " + std::to_string(k) + " references joint " +
                                   std::to_string(head < 0 || head >= nj ? head : tail) +
                                   " but the skeleton has " + std::to_string(nj) + " joints");
  }
  if ((joints[head].rest_position - joints[tail].rest_position).norm() <= 0) {
    return Status::InvalidArgument("bone " + std::to_string(k) + " has zero length");
  }
  if (incoming_bone[tail] >= 0) {
    return Status::InvalidArgument("joint '" + joints[tail].name +
                                   "' is the tail of two bones; a skeleton must be a tree");
  }
  return Status::Ok();
}

// Bones in an order where every parent precedes its children (breadth first from the roots); a
// bone not reached from a root lies on a cycle, so fewer bones come back then.
std::vector<int> ParentsFirstOrder(const std::vector<Bone>& bones) {
  std::vector<std::vector<int>> children(bones.size());
  std::vector<int> order;
  for (int k = 0; k < static_cast<int>(bones.size()); ++k) {
    if (bones[k].parent_bone < 0) {
      order.push_back(k);
    } else {
      children[bones[k].parent_bone].push_back(k);
    }
  }
  for (std::size_t q = 0; q < order.size(); ++q) {
    for (int c : children[order[q]]) order.push_back(c);
  }
  return order;
}

}  // namespace

StatusOr<Skeleton> Skeleton::Create(std::vector<Joint> joints,
                                    std::vector<std::pair<int, int>> bones) {
  return Create(std::move(joints), std::move(bones), {});
}

StatusOr<Skeleton> Skeleton::Create(std::vector<Joint> joints,
                                    std::vector<std::pair<int, int>> bones,
                                    const std::vector<int>& parents) {
  if (!parents.empty() && parents.size() != bones.size()) {
    return Status::InvalidArgument("the skeleton gives " + std::to_string(parents.size()) +
                                   " bone parents for " + std::to_string(bones.size()) + " bones");
  }
  if (joints.empty()) return Status::InvalidArgument("skeleton has no joints");
  if (bones.empty()) return Status::InvalidArgument("skeleton has no bones");
  DEFORM_RETURN_IF_ERROR(CheckJoints(&joints));
  Skeleton s;
  s.incoming_bone_.assign(joints.size(), -1);
  for (int k = 0; k < static_cast<int>(bones.size()); ++k) {
    const auto [head, tail] = bones[k];
    DEFORM_RETURN_IF_ERROR(CheckBone(joints, s.incoming_bone_, k, head, tail));
    s.incoming_bone_[tail] = k;
    s.bones_.push_back({head, tail, -1});
  }
  // Explicit parents: the head joint of such a bone is carried by its parent.
  const int num_bones = static_cast<int>(s.bones_.size());
  for (int k = 0; k < static_cast<int>(parents.size()); ++k) {
    const int parent = parents[k];
    if (parent < 0) continue;
    const std::string bone = "bone " + std::to_string(k);
    if (parent >= num_bones || parent == k) {
      return Status::InvalidArgument(bone + " names parent bone " + std::to_string(parent) +
                                     ", which is not another bone of the " +
                                     std::to_string(num_bones));
    }
    int& carrier = s.incoming_bone_[s.bones_[k].head_joint];
    if (carrier >= 0 && carrier != parent) {
      return Status::InvalidArgument(bone + " names parent bone " + std::to_string(parent) +
                                     " but its head joint '" + joints[s.bones_[k].head_joint].name +
                                     "' is carried by bone " + std::to_string(carrier));
    }
    carrier = parent;
  }
  for (Bone& b : s.bones_) b.parent_bone = s.incoming_bone_[b.head_joint];
  s.bones_parents_first_ = ParentsFirstOrder(s.bones_);
  if (s.bones_parents_first_.size() != s.bones_.size()) {
    return Status::InvalidArgument("skeleton bones form a cycle");
  }
  s.joints_ = std::move(joints);
  return s;
}

std::vector<int> Skeleton::InnerJoints() const {
  std::vector<int> inner;
  for (int j = 0; j < num_joints(); ++j) {
    if (incoming_bone_[j] < 0) continue;
    for (const Bone& b : bones_) {
      if (b.head_joint == j) {
        inner.push_back(j);
        break;
      }
    }
  }
  return inner;
}

StatusOr<int> Skeleton::FindJoint(std::string_view name_or_index) const {
  for (int j = 0; j < num_joints(); ++j) {
    if (joints_[j].name == name_or_index) return j;
  }
  int index = -1;
  if (ParseInt(name_or_index, &index) && index >= 0 && index < num_joints()) return index;
  return Status::NotFound("no joint named '" + std::string(name_or_index) + "' (the skeleton has " +
                          std::to_string(num_joints()) + " joints)");
}

}  // namespace deform
