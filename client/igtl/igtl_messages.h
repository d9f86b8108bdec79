// The OpenIGTLink messages the bridge sends, packed by the OpenIGTLink library into the bytes
// that go on the wire (header and body, CRC included), and the device names they carry.
//
// What a receiver gets (docs/clients/openigtlink.md):
//  - "Skin", POLYDATA with points and triangles: the rest pose's topology, once per connection,
//    before anything else;
//  - "SkinPoints", POLYDATA with the points alone (no vertices, lines, polygons, strips or
//    attributes): one per frame, point i being point i of "Skin" (with --full-frames, "Skin"
//    again instead, triangles included);
//  - one TRANSFORM per skeleton bone (BoneDeviceNames), per frame: the bone's motion from its rest
//    pose, posed = T rest.
// Everything in RAS millimetres (ras_frame.h).
#pragma once

#include <string>
#include <vector>

#include "deform/v1/deform.pb.h"
#include "igtl/ras_frame.h"

namespace deform::igtl_bridge {

inline constexpr char kTopologyDevice[] = "Skin";
inline constexpr char kPointsDevice[] = "SkinPoints";
// OpenIGTLink's device names hold at most this many bytes.
inline constexpr std::size_t kMaxDeviceNameBytes = 20;

// Seconds since the epoch (the header's time stamp); 0: now.
struct MessageTime {
  double seconds = 0;
};

// The full POLYDATA: `positions` float32 x, y, z per vertex (model frame), `triangles` uint32
// little-endian, 3 per triangle, as GetMeshInfo gives them; mapped by `frame` (windings reversed
// when it mirrors).
std::string PackTopology(const std::string& positions, const std::string& triangles,
                         const RasFrame& frame, MessageTime time = {});

// The points-only POLYDATA of one frame's decoded positions (DeformFrame.positions).
std::string PackPoints(const std::string& positions, const RasFrame& frame, MessageTime time = {});

// One TRANSFORM message for `matrix` (row-major 4x4, RAS millimetres).
std::string PackTransform(const std::string& device, const std::array<std::array<float, 4>, 4>& m,
                          MessageTime time = {});

// The device name of every bone of `summary` (bone order): "HEAD-TAIL" after its joints' names
// (e.g. "joint1-joint2"), or "Bone<index>" where that would exceed kMaxDeviceNameBytes or repeat
// another bone's name.
std::vector<std::string> BoneDeviceNames(const deform::v1::MeshSummary& summary);

}  // namespace deform::igtl_bridge
