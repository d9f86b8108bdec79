#include "animation/played_frames.h"

#include <cstdio>

#include "animation/animation_pose.h"
#include "animation/animation_script.h"
#include "core/io/gltf_animation.h"

namespace deform::animation {

StatusOr<std::vector<PlayedFrame>> FramesFromPoseFile(const std::string& path,
                                                      const Skeleton& skeleton) {
  DEFORM_ASSIGN_OR_RETURN(const std::vector<AnimationFrame> lines, ReadAnimationFile(path));
  std::vector<PlayedFrame> frames(lines.size());
  for (std::size_t k = 0; k < lines.size(); ++k) {
    auto resolved = ResolveAnimationFrame(lines[k], skeleton, &frames[k].pose);
    if (!resolved.ok()) return resolved.status().WithContext(path);
    frames[k].line = lines[k].line;
    frames[k].update = PoseUpdateOf(lines[k], 0);
  }
  return frames;
}

deform::v1::PoseUpdate PoseUpdateOfPose(const Skeleton& skeleton, const BoneTransformPose& pose) {
  deform::v1::PoseUpdate update;
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    if (!pose.heads_bone[static_cast<std::size_t>(j)]) continue;
    const Eigen::Quaterniond& q = pose.pose.joint_rotations[static_cast<std::size_t>(j)];
    deform::v1::JointRotation* rotation = update.add_rotations();
    rotation->set_joint(skeleton.joint(j).name);
    rotation->set_w(q.w());
    rotation->set_x(q.x());
    rotation->set_y(q.y());
    rotation->set_z(q.z());
  }
  const RigidTransform& root = pose.pose.root;
  deform::v1::RootTransform* out = update.mutable_root();
  out->mutable_translation()->set_x(root.translation.x());
  out->mutable_translation()->set_y(root.translation.y());
  out->mutable_translation()->set_z(root.translation.z());
  out->mutable_rotation()->set_w(root.rotation.w());
  out->mutable_rotation()->set_x(root.rotation.x());
  out->mutable_rotation()->set_y(root.rotation.y());
  out->mutable_rotation()->set_z(root.rotation.z());
  return update;
}

StatusOr<std::vector<PlayedFrame>> FramesFromGltfAnimation(const std::string& path,
                                                           const Skeleton& skeleton,
                                                           std::string_view name_or_index,
                                                           double fps, std::string* description) {
  DEFORM_ASSIGN_OR_RETURN(const GltfAnimations animations, ReadGltfAnimationsFile(path, skeleton));
  StatusOr<int> index = FindAnimation(animations, name_or_index);
  if (!index.ok()) return index.status().WithContext(path);
  const GltfAnimation& animation = animations.animations[static_cast<std::size_t>(*index)];
  DEFORM_ASSIGN_OR_RETURN(const std::vector<double> times, AnimationFrameTimes(animation, fps));
  std::vector<PlayedFrame> frames(times.size());
  for (std::size_t k = 0; k < times.size(); ++k) {
    StatusOr<BoneTransformPose> pose = SamplePose(animations, *index, times[k]);
    if (!pose.ok()) return pose.status().WithContext(path);
    frames[k].time_s = times[k];
    frames[k].pose = pose->pose;
    frames[k].update = PoseUpdateOfPose(skeleton, *pose);
  }
  char text[160];
  std::snprintf(text, sizeof(text), " (index %d, %.3g s at %.3g fps, %zu frames)", *index,
                animation.end - animation.start, fps, frames.size());
  *description = animation.name + text;
  return frames;
}

}  // namespace deform::animation
