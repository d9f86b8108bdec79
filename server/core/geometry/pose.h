// Poses and forward kinematics.
//
// A pose holds one local rotation per joint, expressed in the rest frame about that joint's rest
// position, plus a root transform applied to the whole skeleton. A joint's rotation moves the bones
// whose head is that joint (its child bones) and, through them, everything below.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/skeleton.h"

namespace deform {

struct RigidTransform {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d Apply(const Eigen::Vector3d& p) const { return rotation * p + translation; }
  // (this * other)(p) = this(other(p)).
  RigidTransform operator*(const RigidTransform& other) const {
    return {rotation * other.rotation, rotation * other.translation + translation};
  }
};

struct Pose {
  std::vector<Eigen::Quaterniond> joint_rotations;  // #joints, unit quaternions
  RigidTransform root;

  static Pose Rest(const Skeleton& skeleton);
};

// One term of a pose: rotate `joint` by `degrees` about either a named degree of freedom of that
// joint (dof >= 0, clamped to its range) or a rest-frame axis (dof == -1).
struct PoseTerm {
  int joint = 0;
  int dof = -1;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  // used when dof == -1
  double degrees = 0;
};

// Resolves an axis name for the joint `term->joint` (a valid joint index): "x", "y" or "z" is
// that rest-frame axis (term->dof = -1), any other name must be one of the joint's degrees of
// freedom (term->dof its index, term->axis its axis). INVALID_ARGUMENT "joint 'knee' has no axis
// 'twist' (known: x, y, z, flexion, ...)" otherwise. The one place pose axes are resolved: the
// pose syntax below and the service's pose updates both come here. Allocates only on error.
Status ResolvePoseAxis(const Skeleton& skeleton, std::string_view axis_name, PoseTerm* term);

// Parses "JOINT:AXIS:DEGREES[,JOINT:AXIS:DEGREES...]" (the syntax of core/base/pose_spec.h) and
// resolves each term against `skeleton`: JOINT is a joint name or 0-based index (FindJoint), AXIS
// as ResolvePoseAxis. "rest" or "" is the rest pose. INVALID_ARGUMENT names the bad term (malformed
// syntax, unknown joint or axis, non-finite angle).
StatusOr<std::vector<PoseTerm>> ParsePoseSpec(std::string_view spec, const Skeleton& skeleton);

// Sets `pose` (sized to the skeleton; its buffers are reused) from terms, composed per joint in
// the order given. Angles of named degrees of freedom outside their range of motion are clamped;
// returns the number of terms clamped. Terms must be finite and refer to valid joints/dofs
// (as ParsePoseSpec guarantees); INVALID_ARGUMENT otherwise.
StatusOr<int> PoseFromTerms(const Skeleton& skeleton, const std::vector<PoseTerm>& terms,
                            Pose* pose);

// Forward kinematics. `bone_transforms` (resized once to #bones) receives, for each bone, the rigid
// transform that maps its rest position to its posed position. Allocation-free when already sized.
void ForwardKinematics(const Skeleton& skeleton, const Pose& pose,
                       std::vector<RigidTransform>* bone_transforms);

// The posed position of joint j given the bone transforms of the same pose: a joint moves with the
// bone that ends there (its incoming bone), a root joint with the root transform.
Eigen::Vector3d PosedJointPosition(const Skeleton& skeleton, const Pose& pose,
                                   const std::vector<RigidTransform>& bone_transforms, int joint);

}  // namespace deform
