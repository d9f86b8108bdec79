// A glTF rig's own animations (the file's "animations": channels on its joint nodes), read,
// checked and sampled into poses of the rig that ReadGltf (core/io/rig_import.h) imports.
//
// Reading: every animation's channels targeting "translation", "rotation" or "scale" of a node
// (channels targeting "weights", morph targets, are ignored, as the import ignores morph targets;
// so are channels without a target node, which an extension defines). Each channel's sampler:
// input SCALAR float times, finite, at least 0 and strictly increasing; output VEC3 float
// (translation, scale) or VEC4 float or normalized integers (rotation, never a zero quaternion),
// as many values as times (LINEAR, STEP) or three per time (CUBICSPLINE: in-tangent, value,
// out-tangent; at least two times). Anything else, an index out of range, a target node with a
// "matrix" (the spec animates TRS nodes only) and two channels of one animation on the same
// node and path are INVALID_ARGUMENT naming the animation, channel or sampler and the accessor;
// more than kMaxAnimationKeys keys in all are RESOURCE_EXHAUSTED. No bytes crash the reader.
//
// Sampling an animation at time t (seconds; before its first key a channel holds its first value,
// after its last its last): each channel's value by its interpolation (STEP: the key at or before
// t; LINEAR: lerp, and for rotations the spec's slerp (shortest path), normalized; CUBICSPLINE: the
// spec's Hermite spline with the tangents scaled by the key interval, rotations normalized); every
// node's local transform is its rest TRS with the animated properties replaced (a node no channel
// targets keeps its own transform); world transforms down the hierarchy; each skeleton bone's
// transform is the joint matrix of the glTF joint at its head (world * inverse bind, as glTF skins
// the mesh), made rigid; and the pose is PoseFromBoneTransforms (core/geometry/
// bone_transform_pose.h) of those, so that root motion carried by a hip under a static top joint
// moves the root.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/bone_transform_pose.h"
#include "core/geometry/mesh.h"
#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"

namespace deform {

// The most keys (times) all channels of a file's animations may hold together.
inline constexpr std::size_t kMaxAnimationKeys = 4'000'000;

enum class AnimationPath { kTranslation, kRotation, kScale };
enum class AnimationInterpolation { kLinear, kStep, kCubicSpline };

struct AnimationChannel {
  int node = -1;
  AnimationPath path = AnimationPath::kTranslation;
  AnimationInterpolation interpolation = AnimationInterpolation::kLinear;
  std::vector<double> times;  // strictly increasing, >= 0
  // components() numbers per output element (rotations x, y, z, w, glTF's order), one element per
  // time, or three per time for CUBICSPLINE (in-tangent, value, out-tangent).
  std::vector<double> values;
  int components() const { return path == AnimationPath::kRotation ? 4 : 3; }
};

struct GltfAnimation {
  std::string name;  // the file's name, "animation<index>" when it has none
  std::vector<AnimationChannel> channels;
  double start = 0;  // the earliest first key of its channels (0 without channels)
  double end = 0;    // the latest last key
};

// A node's local transform as translation, rotation and scale (the matrix T * R * S).
struct NodeTrs {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  Eigen::Matrix4d Matrix() const;
};

// What sampling needs of the file, with its animations.
struct GltfAnimations {
  std::vector<GltfAnimation> animations;
  // The node hierarchy: per node its parent (-1) and its rest local transform (a node with a
  // "matrix" keeps it; no channel targets such a node); every node after its parent.
  std::vector<int> node_parent;
  std::vector<int> parents_first;
  std::vector<NodeTrs> rest_trs;
  std::vector<Eigen::Matrix4d> rest_matrix;
  std::vector<bool> has_matrix;
  // Per skeleton bone: the glTF node of the joint at its head, and that joint's inverse bind
  // matrix (in the skinned mesh's bind space, the space of RigImport::mesh).
  std::vector<int> bone_head_node;
  std::vector<Eigen::Matrix4d> bone_inverse_bind;
  // The skeleton the poses are for (joint rest positions and bones of RigImport::skeleton).
  std::vector<Eigen::Vector3d> joint_rest;
  std::vector<Bone> bones;
};

// Reads the animations of the glTF `bytes` for `skeleton`, the skeleton ReadGltf imported from the
// same bytes (INVALID_ARGUMENT when a bone's head joint is not a joint of the file's skins). The
// file's other errors are ReadGltf's. A file without animations gives an empty list.
StatusOr<GltfAnimations> ReadGltfAnimations(std::string_view bytes, const Skeleton& skeleton,
                                            const MeshLimits& limits = {});
// Reads a file; NOT_FOUND if it cannot be opened; errors carry the path.
StatusOr<GltfAnimations> ReadGltfAnimationsFile(const std::string& path, const Skeleton& skeleton,
                                                const MeshLimits& limits = {});

// The animation named `name_or_index` (a name first; else a 0-based index written in digits).
// NOT_FOUND listing the file's animations otherwise.
StatusOr<int> FindAnimation(const GltfAnimations& animations, std::string_view name_or_index);

// A channel's value at time t: components() numbers (rotations normalized).
Eigen::Vector4d SampleChannel(const AnimationChannel& channel, double t);

// Every node's local transform at time t of animation `animation` (a valid index).
std::vector<Eigen::Matrix4d> SampleLocalTransforms(const GltfAnimations& animations, int animation,
                                                   double t);
// Every node's world transform at time t.
std::vector<Eigen::Matrix4d> SampleWorldTransforms(const GltfAnimations& animations, int animation,
                                                   double t);
// Each skeleton bone's rigid transform at time t (the joint matrix of its head joint).
std::vector<RigidTransform> SampleBoneTransforms(const GltfAnimations& animations, int animation,
                                                 double t);
// The skeleton's pose at time t (see above).
StatusOr<BoneTransformPose> SamplePose(const GltfAnimations& animations, int animation, double t);

// The times at which a player at `fps` frames a second samples the animation: start, start + 1/fps,
// ... and its end (always one time for an animation without duration). INVALID_ARGUMENT for an
// fps that is not positive and finite, RESOURCE_EXHAUSTED beyond `max_frames`.
StatusOr<std::vector<double>> AnimationFrameTimes(const GltfAnimation& animation, double fps,
                                                  std::size_t max_frames = 1'000'000);

}  // namespace deform
