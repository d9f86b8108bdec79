// What one load-test stream observed. Its On* methods are the stream's callbacks: they run on
// gRPC's threads (one at a time per stream), only record numbers, and never block for long.
#pragma once

#include <grpcpp/support/status.h>

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "deform/v1/deform.pb.h"

namespace deform::loadtest {

// Server-side timings of one frame (FrameTimings), in milliseconds.
struct ServerTimings {
  double queue_ms = 0;
  double rhs_ms = 0;
  double solve_ms = 0;
  double encode_ms = 0;
  int batch_frames = 1;      // frames solved in the same pass over the factor
  int solve_parts = 1;       // threads the frame's solve was split over
  double constraint_ms = 0;  // the constraints' corrections after the solve
};

// What the measured frames' constraints (FrameConstraints) did: bone surfaces, volume, tools.
struct ConstraintStats {
  std::uint64_t frames = 0;              // measured frames that carry a constraints report
  std::uint64_t frames_penetrating = 0;  // ... with skin left inside a bone (penetrating_after)
  std::uint64_t frames_unresolved = 0;   // ... flagged unresolved
  std::uint32_t penetrating_after_max = 0;
  double max_depth_after = 0;      // model units
  std::uint64_t contacts_sum = 0;  // for the mean over `frames`
  std::uint32_t contacts_max = 0;
  double volume_change_max_abs = 0;  // relative, over `frames`

  double contacts_mean() const {
    return frames == 0 ? 0.0 : static_cast<double>(contacts_sum) / static_cast<double>(frames);
  }
};

// Counts and samples of one stream. A frame counts as measured when the pose it answers is one of
// the measured period's (its sequence is at least the first measured sequence).
struct StreamStats {
  std::vector<double> latency_ms;           // measured frames: receipt minus echoed send time
  std::vector<ServerTimings> timings;       // measured frames
  ConstraintStats constraints;              // measured frames
  std::uint64_t frames_received = 0;        // measured frames
  std::uint64_t frames_received_total = 0;  // including the warm-up
  std::uint64_t skipped_by_server = 0;      // sum of measured frames' skipped_poses
  std::uint64_t bad_frames = 0;             // positions not 12 bytes per vertex
  std::uint64_t payload_bytes = 0;          // measured frames' positions as they travelled
  double max_gap_ms = 0;  // largest interval between consecutive receipts after the warm-up
  std::int64_t last_receipt_ns = 0;  // MonotonicNanos() of the last frame; 0 before any
  std::uint64_t poses_rejected = 0;
  std::uint64_t stiffness_applied = 0;
  std::uint64_t stiffness_rejected = 0;
  std::vector<double> stiffness_factor_ms;  // Notice.factor_ms of each KIND_STIFFNESS_APPLIED
  grpc::Status final_status;
  bool done = false;
  std::uint64_t reconnects = 0;  // times the stream was opened again (ReconnectPolicy)
};

class StreamRecorder {
 public:
  using Clock = std::chrono::steady_clock;

  // `expected_frames` preallocates the sample buffers; `vertex_count` sets the expected size of a
  // frame's positions.
  StreamRecorder(std::size_t expected_frames, std::size_t vertex_count);

  // Sets where the measured period starts: the first measured pose's sequence, and the time (on
  // MonotonicNanos()'s clock) from which gaps between frames count. Call before the first send.
  void SetMeasureStart(std::uint64_t first_measured_sequence, std::int64_t measure_start_ns);

  void OnFrame(const deform::v1::DeformFrame& frame);
  void OnNotice(const deform::v1::Notice& notice);
  void OnDone(const grpc::Status& status);
  void OnReconnect();

  // Waits until pose `sequence` (or a later one) is answered or rejected, or the stream ends.
  // False on timeout.
  bool WaitAnswered(std::uint64_t sequence, Clock::time_point deadline);
  // Waits until the stream ends. False on timeout.
  bool WaitDone(Clock::time_point deadline);
  bool done();

  // A copy of the stats so far (complete once done()).
  StreamStats Snapshot();

 private:
  const std::size_t position_bytes_;
  std::mutex mu_;
  std::uint64_t first_measured_sequence_ = 0;
  std::int64_t measure_start_ns_ = 0;
  std::condition_variable changed_;
  std::uint64_t last_settled_sequence_ = 0;  // highest sequence answered or rejected
  StreamStats stats_;
};

}  // namespace deform::loadtest
