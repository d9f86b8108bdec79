// The bridge's run: one deform stream on a loaded mesh, its frames served to OpenIGTLink
// receivers (receiver_hub.h) as the messages of igtl_messages.h, joint angles taken from their
// STRING messages (joint_angle_input.h).
//
// The stream uses FRAME_ENCODING_PREDICTED: its frames carry every skeleton bone's transform,
// which the TRANSFORM messages send. A frame the server sent quantized (its residual did not fit)
// has none: receivers then get that frame's points without TRANSFORM messages.
#pragma once

#include <atomic>
#include <string>

#include "deform/v1/deform.pb.h"
#include "igtl/ras_frame.h"
#include "lib/deform_client.h"

namespace deform::igtl_bridge {

struct BridgeSettings {
  std::string listen_host = "127.0.0.1";
  int listen_port = 18944;  // OpenIGTLink's registered port; 0: one the kernel picks
  // Poses a second: the current angles are sent at this rate, so receivers get frames at it (as
  // far as the server keeps up; latest wins). 0: a pose only when a receiver changes an angle.
  // An angle change is sent at once either way.
  double rate_hz = 60.0;
  int max_receivers = 8;
  // Every frame as the full POLYDATA "Skin" (points and triangles) instead of the points-only
  // "SkinPoints": what a receiver that replaces a model with each POLYDATA it gets needs (3D
  // Slicer's OpenIGTLinkIF), at about twice the bytes.
  bool full_frames = false;
  RasFrame frame;
};

// Runs until `stop` is set or the stream ends. Returns the process's exit code: 0 after `stop`,
// 1 (reported on stderr as "deform-igtl-bridge: ...") when the mesh's geometry cannot be fetched,
// the port cannot be bound or the stream ends by itself.
int RunBridge(client::DeformClient& client, const deform::v1::MeshSummary& summary,
              const BridgeSettings& settings, const std::atomic<bool>& stop);

}  // namespace deform::igtl_bridge
