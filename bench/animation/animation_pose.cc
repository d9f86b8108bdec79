#include "animation/animation_pose.h"

#include <Eigen/Geometry>
#include <cmath>

namespace deform::animation {

RigidTransform RootTransformOf(const RootPlacement& root) {
  RigidTransform transform;
  const Eigen::Vector3d axis(root.axis[0], root.axis[1], root.axis[2]);
  if (root.degrees != 0 && axis.norm() > 0) {
    transform.rotation =
        Eigen::Quaterniond(Eigen::AngleAxisd(root.degrees * M_PI / 180.0, axis.normalized()));
    transform.rotation.normalize();
  }
  transform.translation =
      Eigen::Vector3d(root.translation[0], root.translation[1], root.translation[2]);
  return transform;
}

StatusOr<int> ResolveAnimationFrame(const AnimationFrame& frame, const Skeleton& skeleton,
                                    Pose* pose) {
  const auto line_error = [&frame](const Status& status) {
    return Status::InvalidArgument("line " + std::to_string(frame.line) + ": " + status.message());
  };
  auto terms = ParsePoseSpec(frame.pose_spec, skeleton);
  if (!terms.ok()) return line_error(terms.status());
  auto clamped = PoseFromTerms(skeleton, *terms, pose);
  if (!clamped.ok()) return line_error(clamped.status());
  pose->root = frame.has_root ? RootTransformOf(frame.root) : RigidTransform();
  return *clamped;
}

deform::v1::PoseUpdate PoseUpdateOf(const AnimationFrame& frame, std::uint64_t sequence) {
  deform::v1::PoseUpdate update;
  update.set_sequence(sequence);
  for (const PoseSpecTerm& term : frame.terms) {
    deform::v1::JointAngle* angle = update.add_angles();
    angle->set_joint(term.joint);
    angle->set_axis(term.axis);
    angle->set_degrees(term.degrees);
  }
  if (frame.has_root) {
    const RigidTransform root = RootTransformOf(frame.root);
    deform::v1::RootTransform* out = update.mutable_root();
    out->mutable_translation()->set_x(root.translation.x());
    out->mutable_translation()->set_y(root.translation.y());
    out->mutable_translation()->set_z(root.translation.z());
    out->mutable_rotation()->set_w(root.rotation.w());
    out->mutable_rotation()->set_x(root.rotation.x());
    out->mutable_rotation()->set_y(root.rotation.y());
    out->mutable_rotation()->set_z(root.rotation.z());
  }
  return update;
}

}  // namespace deform::animation
