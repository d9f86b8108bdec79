// The frames deform-animation-bench plays: from an animation file (animation_script.h, one pose a
// line) or from a glTF rig's own animation (core/io/gltf_animation.h, sampled at a frame rate).
// Each frame carries the PoseUpdate sent to deformd and the core Pose the local reference measures
// against, made from the same rotations and root, so that the server's pose is the local one.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/bone_transform_pose.h"
#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"
#include "deform/v1/deform.pb.h"

namespace deform::animation {

struct PlayedFrame {
  int line = 0;       // the frame's line in an animation file (0 for a glTF animation)
  double time_s = 0;  // the animation time of a glTF animation's frame
  Pose pose;
  deform::v1::PoseUpdate update;  // sequence 0
};

// The frames of the animation file at `path`, resolved against `skeleton`. INVALID_ARGUMENT
// "PATH: line N: ..." for a malformed line or an unknown joint or axis; NOT_FOUND for a file that
// cannot be read.
StatusOr<std::vector<PlayedFrame>> FramesFromPoseFile(const std::string& path,
                                                      const Skeleton& skeleton);

// The glTF rig at `path` (whose skeleton is `skeleton`) playing its animation `name_or_index` at
// `fps` frames a second over its duration (AnimationFrameTimes). Errors carry the path.
// `description` gets "NAME (index I, D s at F fps, N frames)".
StatusOr<std::vector<PlayedFrame>> FramesFromGltfAnimation(const std::string& path,
                                                           const Skeleton& skeleton,
                                                           std::string_view name_or_index,
                                                           double fps, std::string* description);

// The PoseUpdate of a converted pose: a rotation for every joint heading a bone, and the root.
deform::v1::PoseUpdate PoseUpdateOfPose(const Skeleton& skeleton, const BoneTransformPose& pose);

}  // namespace deform::animation
