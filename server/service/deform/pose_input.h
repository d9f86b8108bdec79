// A client's pose, checked and resolved against a skeleton, ready to become a core Pose.
//
// The Deform stream converts each PoseUpdate as it arrives (on the gRPC thread: name look-ups
// only) and solves it later on a worker. PoseInput's vectors keep their capacity when refilled,
// so a stream that recycles its PoseInputs allocates nothing per pose once warmed up.
#pragma once

#include <Eigen/Geometry>
#include <chrono>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/base/status.h"
#include "core/constraints/tools.h"
#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"
#include "deform/v1/deform.pb.h"

namespace deform::service {

struct PoseInput {
  std::uint64_t sequence = 0;
  std::int64_t client_timestamp_ns = 0;
  std::chrono::steady_clock::time_point arrival;
  std::vector<PoseTerm> angles;                               // in the order sent
  std::vector<std::pair<int, Eigen::Quaterniond>> rotations;  // unit quaternions, in order
  RigidTransform root;                                        // the whole body's placement
  ToolSet tools;  // the frame's tools (ToolsFromProto); empty: none
};

// Fills `input` from `update` (sequence, timestamp, resolved angles and rotations; `arrival` is
// left to the caller). INVALID_ARGUMENT naming the problem for a joint or axis string over its
// length limit (request_limits.h), an unknown joint or axis, an angle or quaternion component that
// is NaN or infinite, an angle beyond kMaxAngleDegrees, a quaternion whose norm is not within
// kQuaternionNormTolerance of 1 (within it, it is normalized; huge components are scaled, never
// squared into infinity), or a root translation that is not finite or beyond 1e9 model units.
Status PoseInputFromProto(const v1::PoseUpdate& update, const Skeleton& skeleton, PoseInput* input);

// Fills `tools` from `update`'s tools, each checked by ValidateTool against the mesh's rest
// bounding box [lower, upper]. INVALID_ARGUMENT naming the tool for more than ToolSet::kMaxTools,
// an unspecified shape, a missing centre (or a capsule's end), or what ValidateTool refuses.
Status ToolsFromProto(const v1::PoseUpdate& update, const Eigen::Vector3d& lower,
                      const Eigen::Vector3d& upper, ToolSet* tools);

// The core pose of `input`: per joint, its rotations (composed in order), then its angles
// (composed in order, named degrees of freedom clamped to their range), and the root transform.
// Returns the number of angles clamped. `pose`'s buffers are reused: allocation-free once sized.
StatusOr<int> PoseFromInput(const Skeleton& skeleton, const PoseInput& input, Pose* pose);

}  // namespace deform::service
