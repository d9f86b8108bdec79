// Converting absolute bone transforms, as animation files and engines hold them, into a pose
// (core/geometry/pose.h: one local rotation per joint plus the root transform). The one home of
// this rule: the client library's PoseFromBoneTransforms (API poses) and the glTF animation
// sampler (core/io/gltf_animation.h) both come here.
//
// Bone k's transform B_k maps its rest position to its posed position (rotation, then
// translation), in the mesh's own frame. The conversion: the root transform is B of the root bone
// (its head joint's rotation then stays identity; a skeleton with several root bones gets the rigid
// fit that carries every root head o_k to B_k(o_k)); every joint j that heads a bone k gets
// R_j = R_parent(k)^T R_k (R_root^T R_k for a root bone). Exact when the transforms are a pose of
// this skeleton: bones that start at one joint turn together, and each bone's head stays on its
// parent's tail (a root bone's on the root's image). The result reports how far the input is from
// that (not an error: an engine's rounding or scale makes it non-zero).
//
// Root motion: when a root bone's transform is the identity (a static top joint) but its first
// child bone's own transform moves that child's head (a common export: the top skin joint static
// and weightless, the hip carrying the translation), the root bone takes that child's transform
// first, so the root transform is the hip's and every bone below is exact; only the root bone
// itself then moves with the hip (exact for linear blend skinning when it carries no weight).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"

namespace deform {

struct BoneTransformPose {
  // A rotation for every joint (identity for joints that head no bone), and the root.
  Pose pose;
  // Per joint: whether it heads a bone (its rotation is the converted one).
  std::vector<bool> heads_bone;
  // Largest angle between the rotations of bones that start at one joint (degrees).
  double sibling_disagreement_degrees = 0;
  // Largest distance between a bone's posed head and its parent's posed tail (model units).
  double joint_gap = 0;
  // The child bone whose transform a root bone took (root motion, see above), or -1.
  int root_taken_from_bone = -1;
};

// `joint_rest` holds the joints' rest positions, `bones` the skeleton's bones (head, tail and
// parent; a Skeleton's bones() or an API summary's), `transforms` one per bone in bone order
// (rotations normalized here). INVALID_ARGUMENT when the counts differ, a bone refers to a joint or
// bone that does not exist, or no bone is a root.
StatusOr<BoneTransformPose> PoseFromBoneTransforms(const std::vector<Eigen::Vector3d>& joint_rest,
                                                   const std::vector<Bone>& bones,
                                                   const std::vector<RigidTransform>& transforms);

// The rigid part of a 4x4 matrix holding a rotation (possibly scaled) and a translation: the
// rotation part orthonormalized (the nearest rotation), the translation column.
RigidTransform RigidTransformFromMatrix(const Eigen::Matrix4d& matrix);

}  // namespace deform
