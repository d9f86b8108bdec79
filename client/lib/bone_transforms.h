// Converting absolute bone transforms, as animation files and engines hold them, into the API's
// pose (deform.v1.PoseUpdate: one local rotation per joint plus the root transform; the meaning is
// written at PoseUpdate in proto/deform/v1/deform.proto).
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

#include <array>
#include <string>
#include <vector>

#include "deform/v1/deform.pb.h"

namespace deform::client {

struct BoneTransform {
  std::array<double, 4> rotation{1, 0, 0, 0};  // unit quaternion w, x, y, z
  std::array<double, 3> translation{0, 0, 0};  // model units
};

// From a 4x4 column-major matrix (glTF's and OpenGL's layout) holding a rotation and a
// translation; the rotation part is orthonormalized.
BoneTransform BoneTransformFromMatrix(const std::array<double, 16>& column_major);

struct PoseConversion {
  deform::v1::PoseUpdate pose;  // `rotations` for every joint heading a bone, and `root`
  // Largest angle between the rotations of bones that start at one joint (degrees).
  double sibling_disagreement_degrees = 0;
  // Largest distance between a bone's posed head and its parent's posed tail (model units).
  double joint_gap = 0;
  // The child bone whose transform a root bone took (root motion, see above), or -1.
  int root_taken_from_bone = -1;
};

// `summary` supplies the skeleton (joints with rest positions, bones with parents), `bones` one
// transform per bone in bone order. False with `error` set when the counts differ or the
// summary's skeleton is malformed; sequence and timestamp of the pose are left 0.
bool PoseFromBoneTransforms(const deform::v1::MeshSummary& summary,
                            const std::vector<BoneTransform>& bones, PoseConversion* result,
                            std::string* error);

}  // namespace deform::client
