// An animation frame (animation_script.h) as the two poses the benchmark needs: the PoseUpdate it
// sends to deformd, and the core Pose the local reference measures against. Both carry the same
// terms in the same order and the same root quaternion, so the server's pose (service/pose_input.h:
// PoseFromTerms, then the root) is the local one.
#pragma once

#include <cstdint>

#include "animation/animation_script.h"
#include "core/base/status.h"
#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"
#include "deform/v1/deform.pb.h"

namespace deform::animation {

// The root placement's rigid transform: the rotation (unit quaternion) then the translation.
RigidTransform RootTransformOf(const RootPlacement& root);

// Resolves `frame`'s terms against `skeleton` into `pose` (ParsePoseSpec, PoseFromTerms) and sets
// its root. Returns the number of angles clamped to a joint's range; INVALID_ARGUMENT
// "line N: ..." for an unknown joint or axis.
StatusOr<int> ResolveAnimationFrame(const AnimationFrame& frame, const Skeleton& skeleton,
                                    Pose* pose);

// The PoseUpdate of `frame` (angles in order, the root when the frame has one), with `sequence`.
deform::v1::PoseUpdate PoseUpdateOf(const AnimationFrame& frame, std::uint64_t sequence);

}  // namespace deform::animation
