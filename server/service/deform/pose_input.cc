#include "service/deform/pose_input.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "service/base/request_limits.h"
#include "service/messages/proto_conversion.h"

namespace deform::service {
namespace {

// Largest translation a root transform may carry, in model units (beyond it float32 frames lose
// every digit of a limb's shape).
constexpr double kMaxRootTranslation = 1e9;

// The unit quaternion of (w, x, y, z): normalized when its norm is within
// kQuaternionNormTolerance of 1. INVALID_ARGUMENT for NaN, infinite or all-zero input and for
// norms further from 1 (1e155 components are a client's bug, not a rotation). The norm is computed
// on the scaled vector, so huge finite components are not squared into infinity.
StatusOr<Eigen::Quaterniond> UnitQuaternion(double w, double x, double y, double z,
                                            const std::string& what) {
  const Eigen::Vector4d q(w, x, y, z);
  if (!q.allFinite()) {
    return Status::InvalidArgument(what + " has a NaN or infinite component");
  }
  const double largest = q.cwiseAbs().maxCoeff();
  if (!(largest > 0)) return Status::InvalidArgument(what + " is the zero quaternion");
  const Eigen::Vector4d scaled = q / largest;
  const double norm = scaled.norm() * largest;
  if (!(std::abs(norm - 1) <= kQuaternionNormTolerance)) {
    char text[64];
    std::snprintf(text, sizeof text, "%.6g", norm);
    return Status::InvalidArgument(what + " has norm " + text + ", not within " +
                                   std::to_string(kQuaternionNormTolerance).substr(0, 3) +
                                   " of 1 (a unit quaternion is expected)");
  }
  const Eigen::Vector4d unit = scaled.normalized();
  return Eigen::Quaterniond(unit[0], unit[1], unit[2], unit[3]);
}

Status RootFromProto(const v1::RootTransform& root, RigidTransform* transform) {
  *transform = RigidTransform();
  if (root.has_rotation()) {
    const v1::Quaternion& r = root.rotation();
    DEFORM_ASSIGN_OR_RETURN(transform->rotation,
                            UnitQuaternion(r.w(), r.x(), r.y(), r.z(), "root rotation"));
  }
  if (root.has_translation()) {
    const v1::Vector3& t = root.translation();
    transform->translation = Eigen::Vector3d(t.x(), t.y(), t.z());
    if (!transform->translation.allFinite() ||
        transform->translation.cwiseAbs().maxCoeff() > kMaxRootTranslation) {
      return Status::InvalidArgument("root translation must be finite and within 1e9 units");
    }
  }
  return Status::Ok();
}

// ToolsFromProto's checks, adding each tool as it passes.
Status AddTools(const v1::PoseUpdate& update, const Eigen::Vector3d& lower,
                const Eigen::Vector3d& upper, ToolSet* tools) {
  tools->count = 0;
  if (update.tools_size() > ToolSet::kMaxTools) {
    return Status::InvalidArgument("at most " + std::to_string(ToolSet::kMaxTools) +
                                   " tools a pose, not " + std::to_string(update.tools_size()));
  }
  for (int t = 0; t < update.tools_size(); ++t) {
    Tool tool;
    DEFORM_RETURN_IF_ERROR(ToolFromProto(update.tools(t), t, lower, upper, &tool));
    tools->Add(tool);
  }
  return Status::Ok();
}

}  // namespace

Status PoseInputFromProto(const v1::PoseUpdate& update, const Skeleton& skeleton,
                          PoseInput* input) {
  input->sequence = update.sequence();
  input->client_timestamp_ns = update.client_timestamp_ns();
  input->angles.clear();
  input->rotations.clear();
  DEFORM_RETURN_IF_ERROR(CheckPoseStrings(update));
  for (const v1::JointRotation& rotation : update.rotations()) {
    auto joint = skeleton.FindJoint(rotation.joint());
    if (!joint.ok()) return Status::InvalidArgument("rotation: " + joint.status().message());
    DEFORM_ASSIGN_OR_RETURN(
        const Eigen::Quaterniond q,
        UnitQuaternion(rotation.w(), rotation.x(), rotation.y(), rotation.z(),
                       "rotation of joint '" + EchoForClient(rotation.joint()) + "'"));
    input->rotations.emplace_back(*joint, q);
  }
  for (const v1::JointAngle& angle : update.angles()) {
    auto joint = skeleton.FindJoint(angle.joint());
    if (!joint.ok()) return Status::InvalidArgument("angle: " + joint.status().message());
    if (!std::isfinite(angle.degrees())) {
      return Status::InvalidArgument("angle of joint '" + EchoForClient(angle.joint()) +
                                     "' axis '" + EchoForClient(angle.axis()) + "' is " +
                                     std::to_string(angle.degrees()) + ", not a finite number");
    }
    if (std::abs(angle.degrees()) > kMaxAngleDegrees) {
      return Status::InvalidArgument(fmt::format(
          "angle of joint '{}' axis '{}' is {:.6g} degrees, beyond the limit of +-{:g} degrees",
          EchoForClient(angle.joint()), EchoForClient(angle.axis()), angle.degrees(),
          kMaxAngleDegrees));
    }
    PoseTerm term;
    term.joint = *joint;
    term.degrees = angle.degrees();
    DEFORM_RETURN_IF_ERROR(ResolvePoseAxis(skeleton, angle.axis(), &term));
    input->angles.push_back(term);
  }
  return RootFromProto(update.root(), &input->root);
}

Status ToolsFromProto(const v1::PoseUpdate& update, const Eigen::Vector3d& lower,
                      const Eigen::Vector3d& upper, ToolSet* tools) {
  Status status = AddTools(update, lower, upper, tools);
  if (!status.ok()) tools->count = 0;
  return status;
}

StatusOr<int> PoseFromInput(const Skeleton& skeleton, const PoseInput& input, Pose* pose) {
  DEFORM_ASSIGN_OR_RETURN(const int clamped, PoseFromTerms(skeleton, input.angles, pose));
  // Rotations come before the angles of their joint: q = R1 R2 ... A1 A2 ...
  for (auto it = input.rotations.rbegin(); it != input.rotations.rend(); ++it) {
    Eigen::Quaterniond& q = pose->joint_rotations[it->first];
    q = it->second * q;
    q.normalize();
  }
  pose->root = input.root;
  return clamped;
}

}  // namespace deform::service
