#include "loadtest/stream_recorder.h"

#include <algorithm>
#include <cmath>

#include "cli/frame_encoding_flag.h"
#include "lib/deform_client.h"

namespace deform::loadtest {

StreamRecorder::StreamRecorder(std::size_t expected_frames, std::size_t vertex_count)
    : position_bytes_(12 * vertex_count) {
  stats_.latency_ms.reserve(expected_frames);
  stats_.timings.reserve(expected_frames);
}

void StreamRecorder::SetMeasureStart(std::uint64_t first_measured_sequence,
                                     std::int64_t measure_start_ns) {
  std::lock_guard<std::mutex> lock(mu_);
  first_measured_sequence_ = first_measured_sequence;
  measure_start_ns_ = measure_start_ns;
}

void StreamRecorder::OnFrame(const deform::v1::DeformFrame& frame) {
  const std::int64_t now_ns = client::MonotonicNanos();
  const deform::v1::FrameTimings& t = frame.timings();
  std::lock_guard<std::mutex> lock(mu_);
  const bool measured = frame.sequence() >= first_measured_sequence_;
  ++stats_.frames_received_total;
  if (frame.positions().size() != position_bytes_) ++stats_.bad_frames;
  if (now_ns >= measure_start_ns_) {
    const std::int64_t previous_ns = std::max(stats_.last_receipt_ns, measure_start_ns_);
    stats_.max_gap_ms =
        std::max(stats_.max_gap_ms, static_cast<double>(now_ns - previous_ns) * 1e-6);
  }
  stats_.last_receipt_ns = now_ns;
  if (measured) {
    ++stats_.frames_received;
    stats_.payload_bytes += cli::FramePayloadBytes(frame);
    stats_.skipped_by_server += frame.skipped_poses();
    stats_.latency_ms.push_back(static_cast<double>(now_ns - frame.client_timestamp_ns()) * 1e-6);
    stats_.timings.push_back({t.queue_ms(), t.rhs_ms(), t.solve_ms(), t.encode_ms(),
                              static_cast<int>(t.batch_frames()), static_cast<int>(t.solve_parts()),
                              t.constraint_ms()});
    if (frame.has_constraints()) {
      const deform::v1::FrameConstraints& c = frame.constraints();
      ConstraintStats& out = stats_.constraints;
      ++out.frames;
      out.frames_penetrating += c.penetrating_after() > 0 ? 1 : 0;
      out.frames_unresolved += c.unresolved() ? 1 : 0;
      out.penetrating_after_max = std::max(out.penetrating_after_max, c.penetrating_after());
      out.max_depth_after = std::max(out.max_depth_after, c.max_depth_after());
      out.contacts_sum += c.contacts();
      out.contacts_max = std::max(out.contacts_max, c.contacts());
      out.volume_change_max_abs = std::max(out.volume_change_max_abs, std::abs(c.volume_change()));
    }
  }
  if (frame.sequence() > last_settled_sequence_) {
    last_settled_sequence_ = frame.sequence();
    changed_.notify_all();
  }
}

void StreamRecorder::OnNotice(const deform::v1::Notice& notice) {
  std::lock_guard<std::mutex> lock(mu_);
  switch (notice.kind()) {
    case deform::v1::Notice::KIND_POSE_REJECTED:
      ++stats_.poses_rejected;
      if (notice.sequence() > last_settled_sequence_) {
        last_settled_sequence_ = notice.sequence();
        changed_.notify_all();
      }
      break;
    case deform::v1::Notice::KIND_STIFFNESS_REJECTED:
      ++stats_.stiffness_rejected;
      break;
    case deform::v1::Notice::KIND_STIFFNESS_APPLIED:
      ++stats_.stiffness_applied;
      stats_.stiffness_factor_ms.push_back(notice.factor_ms());
      break;
    default:
      break;
  }
}

void StreamRecorder::OnDone(const grpc::Status& status) {
  std::lock_guard<std::mutex> lock(mu_);
  stats_.final_status = status;
  stats_.done = true;
  changed_.notify_all();
}

bool StreamRecorder::WaitAnswered(std::uint64_t sequence, Clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(mu_);
  return changed_.wait_until(lock, deadline,
                             [&] { return last_settled_sequence_ >= sequence || stats_.done; });
}

bool StreamRecorder::WaitDone(Clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(mu_);
  return changed_.wait_until(lock, deadline, [&] { return stats_.done; });
}

bool StreamRecorder::done() {
  std::lock_guard<std::mutex> lock(mu_);
  return stats_.done;
}

StreamStats StreamRecorder::Snapshot() {
  std::lock_guard<std::mutex> lock(mu_);
  return stats_;
}

void StreamRecorder::OnReconnect() {
  std::lock_guard<std::mutex> lock(mu_);
  ++stats_.reconnects;
}

}  // namespace deform::loadtest
