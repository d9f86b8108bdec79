#include "core/geometry/pose.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/pose_spec.h"

namespace deform {
namespace {

constexpr double kDegreesToRadians = M_PI / 180.0;

}  // namespace

Pose Pose::Rest(const Skeleton& skeleton) {
  Pose pose;
  pose.joint_rotations.assign(skeleton.num_joints(), Eigen::Quaterniond::Identity());
  return pose;
}

Status ResolvePoseAxis(const Skeleton& skeleton, std::string_view axis_name, PoseTerm* term) {
  if (axis_name == "x" || axis_name == "y" || axis_name == "z") {
    term->dof = -1;
    term->axis = Eigen::Vector3d::Unit(axis_name[0] - 'x');
    return Status::Ok();
  }
  const Joint& joint = skeleton.joint(term->joint);
  for (int d = 0; d < static_cast<int>(joint.dofs.size()); ++d) {
    if (joint.dofs[d].name == axis_name) {
      term->dof = d;
      term->axis = joint.dofs[d].axis;
      return Status::Ok();
    }
  }
  std::string known = "x, y, z";
  for (const DegreeOfFreedom& dof : joint.dofs) known += ", " + dof.name;
  return Status::InvalidArgument("joint '" + joint.name + "' has no axis '" +
                                 std::string(axis_name) + "' (known: " + known + ")");
}

StatusOr<std::vector<PoseTerm>> ParsePoseSpec(std::string_view spec, const Skeleton& skeleton) {
  DEFORM_ASSIGN_OR_RETURN(const std::vector<PoseSpecTerm> written, ParsePoseSpecTerms(spec));
  std::vector<PoseTerm> terms;
  terms.reserve(written.size());
  for (const PoseSpecTerm& term_text : written) {
    PoseTerm term;
    auto joint = skeleton.FindJoint(term_text.joint);
    if (!joint.ok()) return Status::InvalidArgument(joint.status().message());
    term.joint = *joint;
    DEFORM_RETURN_IF_ERROR(ResolvePoseAxis(skeleton, term_text.axis, &term));
    term.degrees = term_text.degrees;
    terms.push_back(term);
  }
  return terms;
}

StatusOr<int> PoseFromTerms(const Skeleton& skeleton, const std::vector<PoseTerm>& terms,
                            Pose* pose) {
  pose->joint_rotations.resize(skeleton.num_joints());
  std::fill(pose->joint_rotations.begin(), pose->joint_rotations.end(),
            Eigen::Quaterniond::Identity());
  pose->root = RigidTransform();
  int clamped = 0;
  for (const PoseTerm& term : terms) {
    if (term.joint < 0 || term.joint >= skeleton.num_joints()) {
      return Status::InvalidArgument("pose names joint " + std::to_string(term.joint) +
                                     " but the skeleton has " +
                                     std::to_string(skeleton.num_joints()));
    }
    if (!std::isfinite(term.degrees)) {
      return Status::InvalidArgument("angle for joint '" + skeleton.joint(term.joint).name +
                                     "' is not finite");
    }
    double degrees = term.degrees;
    Eigen::Vector3d axis = term.axis;
    if (term.dof >= 0) {
      const auto& dofs = skeleton.joint(term.joint).dofs;
      if (term.dof >= static_cast<int>(dofs.size())) {
        return Status::InvalidArgument("joint '" + skeleton.joint(term.joint).name +
                                       "' has no degree of freedom " + std::to_string(term.dof));
      }
      const DegreeOfFreedom& dof = dofs[term.dof];
      axis = dof.axis;
      const double limited = std::clamp(degrees, dof.min_degrees, dof.max_degrees);
      if (limited != degrees) ++clamped;
      degrees = limited;
    } else if (!axis.allFinite() || axis.norm() < 1e-12) {
      return Status::InvalidArgument("pose axis for joint '" + skeleton.joint(term.joint).name +
                                     "' is zero or not finite");
    }
    Eigen::Quaterniond& q = pose->joint_rotations[term.joint];
    q = q * Eigen::Quaterniond(Eigen::AngleAxisd(degrees * kDegreesToRadians, axis.normalized()));
    q.normalize();
  }
  return clamped;
}

void ForwardKinematics(const Skeleton& skeleton, const Pose& pose,
                       std::vector<RigidTransform>* bone_transforms) {
  bone_transforms->resize(skeleton.num_bones());
  for (int k : skeleton.BonesParentsFirst()) {
    const Bone& bone = skeleton.bone(k);
    const Eigen::Vector3d& centre = skeleton.joint(bone.head_joint).rest_position;
    // Rotation about the head joint's rest position, in the rest frame...
    RigidTransform local;
    local.rotation = pose.joint_rotations[bone.head_joint];
    local.translation = centre - local.rotation * centre;
    // ...then carried by the parent bone (or the root transform).
    const RigidTransform& parent =
        bone.parent_bone >= 0 ? (*bone_transforms)[bone.parent_bone] : pose.root;
    (*bone_transforms)[k] = parent * local;
  }
}

Eigen::Vector3d PosedJointPosition(const Skeleton& skeleton, const Pose& pose,
                                   const std::vector<RigidTransform>& bone_transforms, int joint) {
  const int incoming = skeleton.IncomingBone(joint);
  const RigidTransform& t = incoming >= 0 ? bone_transforms[incoming] : pose.root;
  return t.Apply(skeleton.joint(joint).rest_position);
}

}  // namespace deform
