// Plays poses on one Deform stream at a fixed rate and collects the frames that answer them.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lib/deform_client.h"

namespace deform::vr {

struct PlaybackSettings {
  double rate_hz = 90.0;  // pose k is sent at t0 + k / rate_hz (absolute schedule: no drift)
  int poses = 1;          // how many poses to send
  // After the last send: how long to wait for the last pose's frame, and then for the stream to
  // finish after the half-close.
  int answer_timeout_ms = 5000;
  // How frames travel; the client library decodes them into positions.
  deform::v1::FrameEncoding encoding = deform::v1::FRAME_ENCODING_FLOAT32;
};

// Builds pose k (0-based): its angles and rotations. The player sets `sequence` (k + 1) and
// `client_timestamp_ns` (MonotonicNanos() at the send).
using PoseGenerator = std::function<deform::v1::PoseUpdate(int k)>;

struct PlaybackResult {
  int poses_sent = 0;
  int frames_received = 0;
  std::uint64_t skipped_by_server = 0;  // sum of the frames' skipped_poses
  int poses_rejected = 0;               // KIND_POSE_REJECTED notices
  std::string first_rejection;          // "pose rejected: " + the first one's message
  std::vector<double> latency_ms;       // per frame: receipt minus the echoed client timestamp
  std::vector<double> solve_ms;         // per frame: timings.solve_ms
  std::uint64_t payload_bytes = 0;      // all frames' positions as they travelled
  double send_lag_max_ms = 0;           // worst lateness of a send against its schedule
  // The frames' constraints (a mesh with bone surfaces or its volume kept: FrameConstraints).
  int constrained_frames = 0;               // frames that carried a constraint report
  std::uint32_t penetrating_after_max = 0;  // most skin vertices inside a bone in one frame
  double max_depth_after = 0;               // the deepest penetration of any frame, model units
  int frames_unresolved = 0;                // frames that left skin inside a bone
  std::vector<double> constraint_ms;        // per constrained frame: timings.constraint_ms
  bool last_pose_answered = false;
  deform::v1::DeformFrame last_frame;  // the frame answering the last pose, when answered
  // The stream's final status; DEADLINE_EXCEEDED when the last pose was neither answered nor
  // rejected in time, or the stream did not finish after the half-close.
  grpc::Status status;

  // Poses that got no frame and no rejection: superseded (reported by the server or replaced in
  // the client's send queue) or lost when the stream ended.
  int PosesUnanswered() const {
    const int unanswered = poses_sent - frames_received - poses_rejected;
    return unanswered > 0 ? unanswered : 0;
  }
};

// Opens a stream on `mesh_id`, sends `settings.poses` poses from `next_pose`, waits for the last
// one's answer, half-closes and waits for the stream's end. Stops sending early if the stream ends.
PlaybackResult PlayPoses(client::DeformClient& client, const std::string& mesh_id,
                         const PlaybackSettings& settings, const PoseGenerator& next_pose);

}  // namespace deform::vr
