// DeformStream over grpc::ClientBidiReactor.
//
// A hold keeps the call open while the application may still write; it is removed once no more
// writes can come (Close() flushed and half-closed, Cancel(), or the server ended the stream) and
// none is in flight. One write is in flight at a time; the outbox keeps stiffness updates in order
// and lets a newer pose replace a pose still waiting at its end.
#include <condition_variable>
#include <deque>
#include <mutex>
#include <utility>

#include "deform_stream_impl.h"

namespace deform::client::internal {
namespace {

class DeformStreamImpl final
    : public DeformStream,
      public grpc::ClientBidiReactor<deform::v1::DeformRequest, deform::v1::DeformResponse> {
 public:
  DeformStreamImpl(deform::v1::DeformService::Stub* stub, const ClientOptions& options,
                   const deform::v1::DeformStart& start, DeformClient::StreamCallbacks callbacks,
                   std::unique_ptr<codec::FrameDecoder> decoder)
      : callbacks_(std::move(callbacks)), decoder_(std::move(decoder)) {
    AddCallCredentials(options, &context_);
    AddMeshKey(start.mesh_id(), &context_);
    stub->async()->Deform(&context_, this);
    *in_flight_.mutable_start() = start;
    write_in_flight_ = true;
    AddHold();
    StartWrite(&in_flight_);
    StartRead(&response_);
    StartCall();
  }

  ~DeformStreamImpl() override {
    Cancel();
    Wait();
  }

  bool SendPose(const deform::v1::PoseUpdate& pose) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!writable_locked()) return false;
    if (!outbox_.empty() && outbox_.back().has_pose()) {
      *outbox_.back().mutable_pose() = pose;
    } else {
      *outbox_.emplace_back().mutable_pose() = pose;
    }
    PumpLocked();
    return true;
  }

  bool SendStiffness(const deform::v1::StiffnessUpdate& stiffness) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!writable_locked()) return false;
    *outbox_.emplace_back().mutable_stiffness() = stiffness;
    PumpLocked();
    return true;
  }

  void Close() override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closing_) return;
    closing_ = true;
    PumpLocked();
  }

  void Cancel() override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (done_) return;
      cancelled_ = true;
      outbox_.clear();
    }
    context_.TryCancel();
  }

  grpc::Status Wait() override {
    std::unique_lock<std::mutex> lock(mutex_);
    done_cv_.wait(lock, [this] { return done_; });
    return status_;
  }

  void OnWriteDone(bool ok) override {
    std::lock_guard<std::mutex> lock(mutex_);
    write_in_flight_ = false;
    if (!ok) {
      // The call is over (the server finished or the call was cancelled): nothing more to send.
      broken_ = true;
      outbox_.clear();
    }
    PumpLocked();
  }

  void OnReadDone(bool ok) override {
    if (!ok) {
      std::lock_guard<std::mutex> lock(mutex_);
      read_ended_ = true;
      outbox_.clear();
      PumpLocked();
      return;
    }
    if (response_.has_frame()) {
      if (response_.frame().has_encoded()) {
        deform::v1::DeformFrame* frame = response_.mutable_frame();
        const grpc::Status decoded =
            DecodeFrame(frame->encoded(), decoder_.get(), frame->mutable_positions());
        if (!decoded.ok()) {
          {
            std::lock_guard<std::mutex> lock(mutex_);
            decode_error_ = decoded;
          }
          context_.TryCancel();
          return;
        }
      }
      if (callbacks_.on_frame) callbacks_.on_frame(response_.frame());
    } else if (response_.has_notice()) {
      if (callbacks_.on_notice) callbacks_.on_notice(response_.notice());
    }
    StartRead(&response_);
  }

  void OnDone(const grpc::Status& call_status) override {
    grpc::Status status = call_status;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!decode_error_.ok()) status = decode_error_;
    }
    if (callbacks_.on_done) callbacks_.on_done(status);
    std::lock_guard<std::mutex> lock(mutex_);
    status_ = status;
    done_ = true;
    done_cv_.notify_all();
  }

 private:
  bool writable_locked() const {
    return !closing_ && !cancelled_ && !read_ended_ && !broken_ && !done_;
  }

  void PumpLocked() {
    if (write_in_flight_ || hold_released_) return;
    if (!cancelled_ && !read_ended_ && !broken_) {
      if (!outbox_.empty()) {
        in_flight_.Swap(&outbox_.front());
        outbox_.pop_front();
        write_in_flight_ = true;
        StartWrite(&in_flight_);
        return;
      }
      if (!closing_) return;  // more writes may come
      StartWritesDone();
    }
    hold_released_ = true;
    RemoveHold();
  }

  grpc::ClientContext context_;
  DeformClient::StreamCallbacks callbacks_;
  deform::v1::DeformResponse response_;           // read side: one read outstanding at a time
  std::unique_ptr<codec::FrameDecoder> decoder_;  // read side only

  std::mutex mutex_;
  std::condition_variable done_cv_;
  // Guarded by mutex_.
  deform::v1::DeformRequest in_flight_;
  std::deque<deform::v1::DeformRequest> outbox_;
  bool write_in_flight_ = false;
  bool closing_ = false;
  bool cancelled_ = false;
  bool read_ended_ = false;
  bool broken_ = false;
  bool hold_released_ = false;
  bool done_ = false;
  grpc::Status status_;
  grpc::Status decode_error_;  // a frame that did not decode ends the stream with it
};

}  // namespace

std::unique_ptr<DeformStream> StartDeformStream(deform::v1::DeformService::Stub* stub,
                                                const ClientOptions& options,
                                                const deform::v1::DeformStart& start,
                                                DeformClient::StreamCallbacks callbacks,
                                                std::unique_ptr<codec::FrameDecoder> decoder) {
  return std::make_unique<DeformStreamImpl>(stub, options, start, std::move(callbacks),
                                            std::move(decoder));
}

}  // namespace deform::client::internal
