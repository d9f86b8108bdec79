// Converting absolute bone transforms, as animation files and engines hold them, into the API's
// pose (deform.v1.PoseUpdate: one local rotation per joint plus the root transform; the meaning is
// written at PoseUpdate in proto/deform/v1/deform.proto).
//
// The rule itself (bone transforms -> local rotations and root, root motion, the reported
// disagreement) is core/geometry/bone_transform_pose.h; this is its API form.
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
