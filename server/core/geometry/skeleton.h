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
  // The bone whose transform carries this one: the bone whose tail is this bone's head, or one
  // given explicitly (Skeleton::Create's `parents`); -1 for a root bone.
  int parent_bone = -1;
};

class Skeleton {
 public:
  // Validates and builds: joint names unique and non-empty, finite positions, bones reference
  // existing joints, no bone of zero length, each joint is the tail of at most one bone, no cycles,
  // dof axes non-zero (normalized here) and min <= max. Parent bones are derived here.
  static StatusOr<Skeleton> Create(std::vector<Joint> joints,
                                   std::vector<std::pair<int, int>> bones);
  // As above, with explicit parents for rigs whose bones do not meet (a game-engine thigh hangs
  // off the pelvis bone at the hip, away from the pelvis bone's tail): `parents[k]` >= 0 makes
  // bone k a child of that bone, carried by its transform; -1 derives the parent as above. The
  // joint at such a bone's head is then carried by the parent bone (IncomingBone) and is an inner
  // joint (a joint region and a joint centre node), as where bones meet. `parents` is empty or
  // has one entry per bone. INVALID_ARGUMENT, naming the bone, for a parent out of range or
  // itself, a parent that contradicts the bone ending at the head joint, two bones on one head
  // joint with different parents, or a cycle.
  static StatusOr<Skeleton> Create(std::vector<Joint> joints,
                                   std::vector<std::pair<int, int>> bones,
                                   const std::vector<int>& parents);

  int num_joints() const { return static_cast<int>(joints_.size()); }
  int num_bones() const { return static_cast<int>(bones_.size()); }
  const std::vector<Joint>& joints() const { return joints_; }
  const std::vector<Bone>& bones() const { return bones_; }
  const Joint& joint(int j) const { return joints_[j]; }
  const Bone& bone(int b) const { return bones_[b]; }

  // The bone that carries joint j: the bone whose tail is j, or the explicit parent of the bones
  // whose head is j (Create with parents); -1 for a root joint.
  int IncomingBone(int j) const { return incoming_bone_[j]; }
  // Whether bone k's parent was given explicitly and is not the bone ending at its head (what a
  // writer must state: TGF cannot, the project's JSON does).
  bool HasExplicitParent(int k) const {
    const int parent = bones_[k].parent_bone;
    return parent >= 0 && bones_[parent].tail_joint != bones_[k].head_joint;
  }
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
