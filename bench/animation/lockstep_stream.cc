#include "animation/lockstep_stream.h"

#include <chrono>
#include <utility>

namespace deform::animation {

LockstepStream::LockstepStream(client::DeformClient& client, const std::string& mesh_id)
    : shared_(std::make_shared<Shared>()) {
  client::DeformClient::StreamCallbacks callbacks;
  callbacks.on_frame = [shared = shared_](const deform::v1::DeformFrame& frame) {
    const std::int64_t now = client::MonotonicNanos();
    std::lock_guard<std::mutex> lock(shared->mu);
    if (frame.sequence() != shared->awaited || shared->answered) return;
    shared->frame = frame;
    shared->arrival_ns = now;
    shared->answered = true;
    shared->changed.notify_all();
  };
  callbacks.on_notice = [shared = shared_](const deform::v1::Notice& notice) {
    if (notice.kind() != deform::v1::Notice::KIND_POSE_REJECTED) return;
    std::lock_guard<std::mutex> lock(shared->mu);
    if (notice.sequence() != shared->awaited) return;
    shared->rejected = true;
    shared->rejection = notice.message();
    shared->changed.notify_all();
  };
  callbacks.on_done = [shared = shared_](const grpc::Status& status) {
    std::lock_guard<std::mutex> lock(shared->mu);
    shared->done = true;
    shared->final_status = status;
    shared->changed.notify_all();
  };
  stream_ = client.OpenStream(mesh_id, std::move(callbacks));
}

LockstepStream::~LockstepStream() { (void)Finish(5000); }

grpc::Status LockstepStream::Exchange(deform::v1::PoseUpdate pose, int timeout_ms,
                                      AnsweredPose* answer) {
  const std::uint64_t sequence = next_sequence_++;
  pose.set_sequence(sequence);
  {
    std::lock_guard<std::mutex> lock(shared_->mu);
    shared_->awaited = sequence;
    shared_->answered = false;
    shared_->rejected = false;
  }
  const std::int64_t sent_ns = client::MonotonicNanos();
  pose.set_client_timestamp_ns(sent_ns);
  if (!stream_->SendPose(pose)) {
    std::unique_lock<std::mutex> lock(shared_->mu);
    // The stream has ended: its status says why (wait briefly for it to arrive).
    shared_->changed.wait_for(lock, std::chrono::milliseconds(timeout_ms),
                              [&] { return shared_->done; });
    if (shared_->done && !shared_->final_status.ok()) return shared_->final_status;
    return grpc::Status(grpc::StatusCode::UNAVAILABLE,
                        "the stream ended before pose " + std::to_string(sequence) + " was sent");
  }
  std::unique_lock<std::mutex> lock(shared_->mu);
  shared_->changed.wait_for(lock, std::chrono::milliseconds(timeout_ms), [&] {
    return shared_->answered || shared_->rejected || shared_->done;
  });
  if (shared_->answered) {
    answer->frame = std::move(shared_->frame);
    answer->round_trip_ms = static_cast<double>(shared_->arrival_ns - sent_ns) * 1e-6;
    return grpc::Status::OK;
  }
  if (shared_->rejected) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        "pose " + std::to_string(sequence) + " rejected: " + shared_->rejection);
  }
  if (shared_->done) {
    return shared_->final_status.ok() ? grpc::Status(grpc::StatusCode::UNAVAILABLE,
                                                     "the stream ended before pose " +
                                                         std::to_string(sequence) + " was answered")
                                      : shared_->final_status;
  }
  return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                      "no frame for pose " + std::to_string(sequence) + " within " +
                          std::to_string(timeout_ms) + " ms");
}

grpc::Status LockstepStream::Finish(int timeout_ms) {
  if (!finished_) {
    finished_ = true;
    stream_->Close();
  }
  std::unique_lock<std::mutex> lock(shared_->mu);
  if (!shared_->changed.wait_for(lock, std::chrono::milliseconds(timeout_ms),
                                 [&] { return shared_->done; })) {
    lock.unlock();
    stream_->Cancel();
    (void)stream_->Wait();
    return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                        "the stream did not finish within " + std::to_string(timeout_ms) + " ms");
  }
  return shared_->final_status;
}

}  // namespace deform::animation
