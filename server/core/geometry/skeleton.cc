#include "core/geometry/skeleton.h"

#include <cmath>
#include <unordered_set>

#include "core/base/text.h"

namespace deform {
namespace {

bool IsFinite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

StatusOr<Skeleton> Skeleton::Create(std::vector<Joint> joints,
                                    std::vector<std::pair<int, int>> bones) {
  const int nj = static_cast<int>(joints.size());
  if (nj == 0) return Status::InvalidArgument("skeleton has no joints");
  if (bones.empty()) return Status::InvalidArgument("skeleton has no bones");
  std::unordered_set<std::string> names;
  for (int j = 0; j < nj; ++j) {
    Joint& joint = joints[j];
    if (joint.name.empty())
      return Status::InvalidArgument("joint " + std::to_string(j) + " has no name");
    if (!names.insert(joint.name).second) {
      return Status::InvalidArgument("joint name '" + joint.name + "' is used twice");
    }
    if (!IsFinite(joint.rest_position)) {
      return Status::InvalidArgument("joint '" + joint.name + "' has a non-finite position");
    }
    std::unordered_set<std::string> dof_names;
    for (DegreeOfFreedom& dof : joint.dofs) {
      if (dof.name.empty() || dof.name == "x" || dof.name == "y" || dof.name == "z") {
        return Status::InvalidArgument("joint '" + joint.name +
                                       "' has a degree of freedom without a usable name");
      }
      if (!dof_names.insert(dof.name).second) {
        return Status::InvalidArgument("joint '" + joint.name + "' names degree of freedom '" +
                                       dof.name + "' twice");
      }
      const double length = dof.axis.norm();
      if (!std::isfinite(length) || length < 1e-12) {
        return Status::InvalidArgument("degree of freedom '" + joint.name + ":" + dof.name +
                                       "' has a zero or non-finite axis");
      }
      dof.axis /= length;
      if (!std::isfinite(dof.min_degrees) || !std::isfinite(dof.max_degrees) ||
          dof.min_degrees > dof.max_degrees) {
        return Status::InvalidArgument("degree of freedom '" + joint.name + ":" + dof.name +
                                       "' has an invalid range");
      }
    }
  }

  Skeleton s;
  s.incoming_bone_.assign(nj, -1);
  for (int k = 0; k < static_cast<int>(bones.size()); ++k) {
    const auto [head, tail] = bones[k];
    if (head < 0 || head >= nj || tail < 0 || tail >= nj) {
      return Status::InvalidArgument("bone " + std::to_string(k) + " references joint " +
                                     std::to_string(head < 0 || head >= nj ? head : tail) +
                                     " but the skeleton has " + std::to_string(nj) + " joints");
    }
    if ((joints[head].rest_position - joints[tail].rest_position).norm() <= 0) {
      return Status::InvalidArgument("bone " + std::to_string(k) + " has zero length");
    }
    if (s.incoming_bone_[tail] >= 0) {
      return Status::InvalidArgument("joint '" + joints[tail].name +
                                     "' is the tail of two bones; a skeleton must be a tree");
    }
    s.incoming_bone_[tail] = k;
    s.bones_.push_back({head, tail, -1});
  }
  for (Bone& b : s.bones_) b.parent_bone = s.incoming_bone_[b.head_joint];

  // Parents-first order; a bone not reached from a root lies on a cycle.
  std::vector<std::vector<int>> children(s.bones_.size());
  std::vector<int> roots;
  for (int k = 0; k < static_cast<int>(s.bones_.size()); ++k) {
    if (s.bones_[k].parent_bone < 0) {
      roots.push_back(k);
    } else {
      children[s.bones_[k].parent_bone].push_back(k);
    }
  }
  for (size_t q = 0; q < roots.size(); ++q) {
    s.bones_parents_first_.push_back(roots[q]);
    for (int c : children[roots[q]]) roots.push_back(c);
  }
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
