// Bounds on what a client may send and on how much of it the server repeats back.
//
// Every client string the service keeps or echoes has a length limit, checked before it is used:
// a string over its limit is INVALID_ARGUMENT naming the field, its length and the limit, and is
// never echoed. Strings within their limits are echoed only escaped and cut (EchoForClient), and
// every status message leaving the server is cut to kMaxStatusMessageBytes (status_mapping.cc),
// so no error can overflow gRPC's metadata limit. Pure functions, thread-safe, no gRPC here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/base/status.h"
#include "deform/v1/deform.pb.h"

namespace deform::service {

// LoadMeshHeader.name.
inline constexpr std::size_t kMaxMeshNameBytes = 256;
// Every mesh_id a request names (GetMeshInfo, UnloadMesh, Deform's start).
inline constexpr std::size_t kMaxMeshIdBytes = 128;
// Joint names (or indices) in poses, stiffness updates and method options.
inline constexpr std::size_t kMaxJointNameBytes = 256;
// Axis names in poses ("x", "flexion", ...).
inline constexpr std::size_t kMaxAxisNameBytes = 64;
// Client bytes repeated in one error or notice message (escaped, then cut).
inline constexpr std::size_t kMaxEchoBytes = 64;
// A status message sent to a client, whatever produced it.
inline constexpr std::size_t kMaxStatusMessageBytes = 1024;
// Largest joint angle accepted, in degrees (100 turns); beyond it a pose is rejected.
inline constexpr double kMaxAngleDegrees = 36000;
// A quaternion's norm must be within this of 1; it is normalized within it, rejected beyond.
inline constexpr double kQuaternionNormTolerance = 0.1;

// OK, or INVALID_ARGUMENT "<field> is N bytes long, over the limit of L bytes".
Status CheckLength(std::string_view value, std::size_t limit, std::string_view field);

// `status`, from checking the request field at path `field`, naming that field as its subject
// (Status::subject, which status_mapping.h turns into a BadRequest): an INVALID_ARGUMENT without
// a subject gets `field`, one whose subject is a path inside the field gets it prefixed
// ("options" and "region_radii[0].joint" give "options.region_radii[0].joint"). Other statuses,
// whose subject is no field path, are returned as they are. The message is not changed.
Status InField(const Status& status, const std::string& field);

// `text` escaped (EscapeForLog) and cut after kMaxEchoBytes input bytes, with its length when cut:
// what an error message may repeat of a client string.
std::string EchoForClient(std::string_view text);

// `message` cut to kMaxStatusMessageBytes (ending in "... (N bytes)" when cut).
std::string BoundStatusMessage(std::string message);

// The string fields of a pose, a stiffness update, method options and a load header against
// their limits. Field names in the messages are the proto's paths ("angles[2].axis").
Status CheckPoseStrings(const v1::PoseUpdate& pose);
Status CheckStiffnessStrings(const v1::StiffnessUpdate& stiffness);
Status CheckMethodOptionStrings(const v1::MethodOptions& options);
Status CheckLoadHeaderStrings(const v1::LoadMeshHeader& header);

// An upload's declared size against `limit`: RESOURCE_EXHAUSTED with the real figures when the
// mesh bytes plus the skeleton and weights bytes exceed it. The sum is computed without
// overflow (a declared 2^64-1 bytes is reported as such).
Status CheckUploadSize(std::uint64_t mesh_bytes, std::uint64_t skeleton_bytes,
                       std::uint64_t weights_bytes, std::uint64_t limit);

}  // namespace deform::service
