// A skeleton: joints at rest positions joined by bones into a forest, with each joint's named
// degrees of freedom (clinical angles) and their ranges of motion.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"

namespace deform {

// One named rotational degree of freedom of a joint, e.g. the knee's "flexion".
struct DegreeOfFreedom {
  std::string name;
  Eigen::Vector3d axis;       // unit axis in the rest frame (carried along by the parent bones)
  double min_degrees = -180;  // range of motion; angles outside are clamped
  double max_degrees = 180;
};

struct Joint {
  std::string name;               // unique; TGF joints are named "joint0", "joint1", ...
  Eigen::Vector3d rest_position;  // model units
  std::vector<DegreeOfFreedom> dofs;
};

struct Bone {
  int head_joint = -1;  // the parent side: rotations of this joint move the bone
  int tail_joint = -1;
  int parent_bone = -1;  // the bone whose tail is this bone's head, or -1 for a root bone
};

class Skeleton {
 public:
  // Validates and builds: joint names unique and non-empty, finite positions, bones reference
  // existing joints, no bone of zero length, each joint is the tail of at most one bone, no cycles,
  // dof axes non-zero (normalised here) and min <= max. Parent bones are derived here.
  static StatusOr<Skeleton> Create(std::vector<Joint> joints,
                                   std::vector<std::pair<int, int>> bones);

  int num_joints() const { return static_cast<int>(joints_.size()); }
  int num_bones() const { return static_cast<int>(bones_.size()); }
  const std::vector<Joint>& joints() const { return joints_; }
  const std::vector<Bone>& bones() const { return bones_; }
  const Joint& joint(int j) const { return joints_[j]; }
  const Bone& bone(int b) const { return bones_[b]; }

  // The bone whose tail is joint j, or -1 (a root joint).
  int IncomingBone(int j) const { return incoming_bone_[j]; }
  // Bones in an order where every parent precedes its children.
  const std::vector<int>& BonesParentsFirst() const { return bones_parents_first_; }
  // Joints where a parent bone and at least one child bone meet (rotation centres: knee, ankle...).
  // Each gets a joint centre node in the deformation model.
  std::vector<int> InnerJoints() const;

  // A joint by name, or by its 0-based index written as a decimal string.
  StatusOr<int> FindJoint(std::string_view name_or_index) const;

 private:
  std::vector<Joint> joints_;
  std::vector<Bone> bones_;
  std::vector<int> incoming_bone_;
  std::vector<int> bones_parents_first_;
};

}  // namespace deform
