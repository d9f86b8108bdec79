#include "service/pose_input.h"

#include <cmath>
#include <string>

namespace deform::service {

Status PoseInputFromProto(const v1::PoseUpdate& update, const Skeleton& skeleton,
                          PoseInput* input) {
  input->sequence = update.sequence();
  input->client_timestamp_ns = update.client_timestamp_ns();
  input->angles.clear();
  input->rotations.clear();
  for (const v1::JointRotation& rotation : update.rotations()) {
    auto joint = skeleton.FindJoint(rotation.joint());
    if (!joint.ok()) return Status::InvalidArgument("rotation: " + joint.status().message());
    const Eigen::Quaterniond q(rotation.w(), rotation.x(), rotation.y(), rotation.z());
    if (!q.coeffs().allFinite()) {
      return Status::InvalidArgument("rotation of joint '" + rotation.joint() +
                                     "' has a NaN or infinite component");
    }
    const double norm = q.norm();
    if (!(norm > 1e-12)) {
      return Status::InvalidArgument("rotation of joint '" + rotation.joint() +
                                     "' is the zero quaternion");
    }
    input->rotations.emplace_back(*joint, Eigen::Quaterniond(q.coeffs() / norm));
  }
  for (const v1::JointAngle& angle : update.angles()) {
    auto joint = skeleton.FindJoint(angle.joint());
    if (!joint.ok()) return Status::InvalidArgument("angle: " + joint.status().message());
    if (!std::isfinite(angle.degrees())) {
      return Status::InvalidArgument("angle of joint '" + angle.joint() + "' axis '" +
                                     angle.axis() + "' is " + std::to_string(angle.degrees()) +
                                     ", not a finite number");
    }
    PoseTerm term;
    term.joint = *joint;
    term.degrees = angle.degrees();
    DEFORM_RETURN_IF_ERROR(ResolvePoseAxis(skeleton, angle.axis(), &term));
    input->angles.push_back(term);
  }
  return Status::Ok();
}

StatusOr<int> PoseFromInput(const Skeleton& skeleton, const PoseInput& input, Pose* pose) {
  DEFORM_ASSIGN_OR_RETURN(const int clamped, PoseFromTerms(skeleton, input.angles, pose));
  // Rotations come before the angles of their joint: q = R1 R2 ... A1 A2 ...
  for (auto it = input.rotations.rbegin(); it != input.rotations.rend(); ++it) {
    Eigen::Quaterniond& q = pose->joint_rotations[it->first];
    q = it->second * q;
    q.normalize();
  }
  return clamped;
}

}  // namespace deform::service
