#include "vr/pose_player.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "cli/frame_encoding_flag.h"

namespace deform::vr {
namespace {

using Clock = std::chrono::steady_clock;

// State shared between the sender (caller's thread) and the stream's callbacks (gRPC threads).
class PlaybackState {
 public:
  PlaybackState(std::uint64_t last_sequence, int expected_frames) : last_sequence_(last_sequence) {
    result_.latency_ms.reserve(static_cast<std::size_t>(expected_frames));
    result_.solve_ms.reserve(static_cast<std::size_t>(expected_frames));
  }

  void OnFrame(const deform::v1::DeformFrame& frame) {
    const std::int64_t now_ns = client::MonotonicNanos();
    std::lock_guard<std::mutex> lock(mu_);
    ++result_.frames_received;
    result_.skipped_by_server += frame.skipped_poses();
    result_.latency_ms.push_back(static_cast<double>(now_ns - frame.client_timestamp_ns()) * 1e-6);
    result_.solve_ms.push_back(frame.timings().solve_ms());
    if (frame.has_constraints()) {
      const deform::v1::FrameConstraints& c = frame.constraints();
      ++result_.constrained_frames;
      result_.penetrating_after_max =
          std::max(result_.penetrating_after_max, c.penetrating_after());
      result_.max_depth_after = std::max(result_.max_depth_after, c.max_depth_after());
      if (c.unresolved()) ++result_.frames_unresolved;
      result_.constraint_ms.push_back(frame.timings().constraint_ms());
    }
    result_.payload_bytes += cli::FramePayloadBytes(frame);
    if (frame.sequence() == last_sequence_) {
      result_.last_frame = frame;
      result_.last_pose_answered = true;
      last_settled_ = true;
      changed_.notify_all();
    }
  }

  void OnNotice(const deform::v1::Notice& notice) {
    if (notice.kind() != deform::v1::Notice::KIND_POSE_REJECTED) return;
    std::lock_guard<std::mutex> lock(mu_);
    if (result_.poses_rejected++ == 0) {
      result_.first_rejection = "pose rejected: " + notice.message();
    }
    if (notice.sequence() == last_sequence_) {
      last_settled_ = true;
      changed_.notify_all();
    }
  }

  void OnDone(const grpc::Status& status) {
    std::lock_guard<std::mutex> lock(mu_);
    result_.status = status;
    done_ = true;
    changed_.notify_all();
  }

  bool done() {
    std::lock_guard<std::mutex> lock(mu_);
    return done_;
  }

  // Waits until the last pose is answered or rejected, or the stream ends. False on timeout.
  bool WaitLastSettled(Clock::time_point deadline) {
    std::unique_lock<std::mutex> lock(mu_);
    return changed_.wait_until(lock, deadline, [&] { return last_settled_ || done_; });
  }

  // Waits until the stream ends. False on timeout.
  bool WaitDone(Clock::time_point deadline) {
    std::unique_lock<std::mutex> lock(mu_);
    return changed_.wait_until(lock, deadline, [&] { return done_; });
  }

  // Moves the result out. Call only after the stream has ended (no callback runs any more).
  PlaybackResult TakeResult() {
    std::lock_guard<std::mutex> lock(mu_);
    return std::move(result_);
  }

 private:
  const std::uint64_t last_sequence_;
  std::mutex mu_;
  std::condition_variable changed_;
  bool last_settled_ = false;
  bool done_ = false;
  PlaybackResult result_;
};

}  // namespace

PlaybackResult PlayPoses(client::DeformClient& client, const std::string& mesh_id,
                         const PlaybackSettings& settings, const PoseGenerator& next_pose) {
  PlaybackState state(static_cast<std::uint64_t>(settings.poses), settings.poses);
  client::DeformClient::StreamCallbacks callbacks;
  callbacks.on_frame = [&state](const deform::v1::DeformFrame& frame) { state.OnFrame(frame); };
  callbacks.on_notice = [&state](const deform::v1::Notice& notice) { state.OnNotice(notice); };
  callbacks.on_done = [&state](const grpc::Status& status) { state.OnDone(status); };
  client::DeformClient::StreamOptions options;
  options.encoding = settings.encoding;
  std::unique_ptr<client::DeformStream> stream =
      client.OpenStream(mesh_id, std::move(callbacks), options);
  if (stream == nullptr) {
    PlaybackResult failed;
    failed.status = grpc::Status(grpc::StatusCode::INTERNAL, "the stream could not be opened");
    return failed;
  }

  int sent = 0;
  double send_lag_max_ms = 0;
  const Clock::time_point t0 = Clock::now();
  const std::chrono::duration<double> period(1.0 / settings.rate_hz);
  for (int k = 0; k < settings.poses; ++k) {
    const Clock::time_point scheduled =
        t0 + std::chrono::duration_cast<Clock::duration>(k * period);
    std::this_thread::sleep_until(scheduled);
    if (state.done()) break;
    deform::v1::PoseUpdate pose = next_pose(k);
    pose.set_sequence(static_cast<std::uint64_t>(k) + 1);
    pose.set_client_timestamp_ns(client::MonotonicNanos());
    const double lag_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - scheduled).count();
    if (lag_ms > send_lag_max_ms) send_lag_max_ms = lag_ms;
    if (!stream->SendPose(pose)) break;
    ++sent;
  }

  const std::chrono::milliseconds timeout(settings.answer_timeout_ms);
  const bool settled = sent < settings.poses || state.WaitLastSettled(Clock::now() + timeout);
  bool finished = false;
  if (settled) {
    stream->Close();
    finished = state.WaitDone(Clock::now() + timeout);
  }
  if (!finished) stream->Cancel();
  const grpc::Status final_status = stream->Wait();

  PlaybackResult result = state.TakeResult();
  result.status = final_status;
  result.poses_sent = sent;
  result.send_lag_max_ms = send_lag_max_ms;
  if (!settled) {
    result.status =
        grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                     "no frame for pose " + std::to_string(settings.poses) + " within " +
                         std::to_string(settings.answer_timeout_ms) + " ms");
  } else if (!finished) {
    result.status =
        grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                     "the stream did not finish within " +
                         std::to_string(settings.answer_timeout_ms) + " ms of the half-close");
  }
  return result;
}

}  // namespace deform::vr
