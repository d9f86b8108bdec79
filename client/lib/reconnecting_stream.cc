// A Deform stream that opens itself again when its server is lost.
//
// One plain stream (`current_`) at a time. Its on_done with UNAVAILABLE marks the stream lost; the
// stream's own thread (`reconnector_`) then drops it, waits the backoff and opens the next, to
// which it re-sends the latest pose and stiffness update. Each plain stream's callbacks carry its
// generation, so a late callback of an old one is ignored. The application's on_done runs once:
// when a plain stream ends otherwise than UNAVAILABLE, or the policy gives up, or the application
// closed or cancelled the stream while it was lost.
#include "reconnecting_stream.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <random>
#include <thread>
#include <utility>

#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"

namespace deform::client::internal {
namespace {

using Clock = std::chrono::steady_clock;

class ReconnectingStream final : public DeformStream {
 public:
  ReconnectingStream(StreamOpener open, DeformClient::StreamCallbacks callbacks,
                     const ReconnectPolicy& policy)
      : open_(std::move(open)),
        user_(std::move(callbacks)),
        policy_(policy),
        jitter_(std::random_device{}()) {
    std::shared_ptr<DeformStream> first = open_(CallbacksFor(0));
    std::lock_guard<std::mutex> lock(mutex_);
    if (first != nullptr) {
      current_ = std::move(first);
    } else if (!lost_) {
      lost_ = true;
      lost_status_ = grpc::Status(grpc::StatusCode::UNAVAILABLE, "the stream could not start");
      lost_at_ = Clock::now();
    }
    reconnector_ = std::thread([this] { Run(); });
  }

  ~ReconnectingStream() override {
    Cancel();
    Wait();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    reconnector_.join();
  }

  // The plain stream's methods are called without mutex_ held: they may run its callbacks, which
  // take it.
  bool SendPose(const deform::v1::PoseUpdate& pose) override {
    std::shared_ptr<DeformStream> current;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (done_ || closing_ || cancelled_) return false;
      latest_pose_ = pose;
      has_pose_ = true;
      if (!lost_) current = current_;
    }
    if (current != nullptr) (void)current->SendPose(pose);
    return true;  // while lost, it waits for the next stream
  }

  bool SendStiffness(const deform::v1::StiffnessUpdate& stiffness) override {
    std::shared_ptr<DeformStream> current;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (done_ || closing_ || cancelled_) return false;
      latest_stiffness_ = stiffness;
      has_stiffness_ = true;
      if (!lost_) current = current_;
    }
    if (current != nullptr) (void)current->SendStiffness(stiffness);
    return true;
  }

  void Close() override {
    std::shared_ptr<DeformStream> current;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closing_ = true;
      if (!lost_) current = current_;
    }
    wake_.notify_all();
    if (current != nullptr) current->Close();
  }

  void Cancel() override {
    std::shared_ptr<DeformStream> current;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (done_) return;
      cancelled_ = true;
      if (!lost_) current = current_;
    }
    wake_.notify_all();
    if (current != nullptr) current->Cancel();
  }

  grpc::Status Wait() override {
    std::unique_lock<std::mutex> lock(mutex_);
    done_cv_.wait(lock, [this] { return done_; });
    return status_;
  }

 private:
  DeformClient::StreamCallbacks CallbacksFor(int generation) {
    DeformClient::StreamCallbacks callbacks;
    callbacks.on_frame = [this, generation](const deform::v1::DeformFrame& frame) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (generation != generation_) return;
        attempts_ = 0;  // healthy again: the next loss starts a fresh budget
      }
      if (user_.on_frame) user_.on_frame(frame);
    };
    callbacks.on_notice = [this, generation](const deform::v1::Notice& notice) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (generation != generation_) return;
      }
      if (user_.on_notice) user_.on_notice(notice);
    };
    callbacks.on_done = [this, generation](const grpc::Status& status) {
      std::unique_lock<std::mutex> lock(mutex_);
      if (generation != generation_ || done_) return;
      // UNAVAILABLE: the server went away or cannot serve now. CANCELLED that the application did
      // not ask for: a proxy between us reset the stream (HAProxy does when its server dies).
      const bool lost = status.error_code() == grpc::StatusCode::UNAVAILABLE ||
                        status.error_code() == grpc::StatusCode::CANCELLED;
      if (lost && !cancelled_ && !closing_) {
        if (attempts_ == 0) lost_at_ = Clock::now();
        lost_ = true;
        lost_status_ = status;
        wake_.notify_all();
        return;
      }
      FinishLocked(status, &lock);
    };
    return callbacks;
  }

  // Ends the stream for the application; unlocks `lock` for its callback.
  void FinishLocked(const grpc::Status& status, std::unique_lock<std::mutex>* lock) {
    if (done_ || finishing_) return;
    finishing_ = true;
    lock->unlock();
    if (user_.on_done) user_.on_done(status);
    lock->lock();
    status_ = status;
    done_ = true;
    done_cv_.notify_all();
  }

  int BackoffMs() {
    const int hinted = RetryDelayMs(lost_status_);
    int delay = hinted;
    if (delay <= 0) {
      delay = policy_.initial_backoff_ms;
      for (int i = 1; i < attempts_ && delay < policy_.max_backoff_ms; ++i) delay *= 2;
      delay = std::min(delay, policy_.max_backoff_ms);
    }
    std::uniform_real_distribution<double> spread(0.0, 0.2);
    return std::max(1, static_cast<int>(delay * (1.0 + spread(jitter_))));
  }

  void Run() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stop_ || lost_ || (done_ && current_ != nullptr); });
      if (stop_) return;
      if (!lost_) {  // ended for good: let the last plain stream go
        std::shared_ptr<DeformStream> last = std::move(current_);
        lock.unlock();
        last.reset();
        lock.lock();
        continue;
      }
      std::shared_ptr<DeformStream> old = std::move(current_);
      lock.unlock();
      old.reset();  // ended already: its destructor returns at once
      lock.lock();
      for (;;) {
        if (cancelled_ || closing_) {
          FinishLocked(
              cancelled_ ? grpc::Status(grpc::StatusCode::CANCELLED, "cancelled") : lost_status_,
              &lock);
          lost_ = false;
          break;
        }
        if (Clock::now() - lost_at_ >= std::chrono::milliseconds(policy_.give_up_after_ms)) {
          FinishLocked(lost_status_, &lock);
          lost_ = false;
          break;
        }
        ++attempts_;
        const int delay = BackoffMs();
        if (wake_.wait_for(lock, std::chrono::milliseconds(delay),
                           [this] { return stop_ || cancelled_ || closing_; })) {
          if (stop_) return;
          continue;
        }
        const int generation = ++generation_;
        const grpc::Status lost = lost_status_;
        const int attempt = attempts_;
        lost_ = false;
        lock.unlock();
        std::shared_ptr<DeformStream> fresh = open_(CallbacksFor(generation));
        lock.lock();
        if (fresh == nullptr) {
          lost_ = true;
          continue;
        }
        current_ = fresh;
        const bool has_pose = has_pose_, has_stiffness = has_stiffness_;
        const deform::v1::PoseUpdate pose = latest_pose_;
        const deform::v1::StiffnessUpdate stiffness = latest_stiffness_;
        lock.unlock();
        if (has_pose) (void)fresh->SendPose(pose);
        if (has_stiffness) (void)fresh->SendStiffness(stiffness);
        if (user_.on_reconnect) user_.on_reconnect(lost, attempt);
        lock.lock();
        // The application closed or cancelled meanwhile: the fresh stream must hear of it.
        if (closing_ || cancelled_) {
          const bool cancel = cancelled_;
          lock.unlock();
          if (cancel) {
            fresh->Cancel();
          } else {
            fresh->Close();
          }
          lock.lock();
        }
        break;  // lost_ may be set again already by the fresh stream's on_done: handled above
      }
    }
  }

  const StreamOpener open_;
  const DeformClient::StreamCallbacks user_;
  const ReconnectPolicy policy_;
  std::thread reconnector_;

  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_cv_;
  // Guarded by mutex_.
  std::shared_ptr<DeformStream> current_;
  int generation_ = 0;
  bool lost_ = false;
  grpc::Status lost_status_;
  Clock::time_point lost_at_;
  int attempts_ = 0;  // since the last frame
  deform::v1::PoseUpdate latest_pose_;
  bool has_pose_ = false;
  deform::v1::StiffnessUpdate latest_stiffness_;
  bool has_stiffness_ = false;
  bool closing_ = false;
  bool cancelled_ = false;
  bool finishing_ = false;
  bool done_ = false;
  bool stop_ = false;
  grpc::Status status_;
  std::mt19937 jitter_;
};

}  // namespace

int RetryDelayMs(const grpc::Status& status) {
  if (status.error_details().empty()) return 0;
  google::rpc::Status details;
  if (!details.ParseFromString(status.error_details())) return 0;
  for (const auto& detail : details.details()) {
    google::rpc::RetryInfo retry;
    if (detail.UnpackTo(&retry) && retry.has_retry_delay()) {
      const long long ms =
          retry.retry_delay().seconds() * 1000 + retry.retry_delay().nanos() / 1'000'000;
      return static_cast<int>(std::clamp<long long>(ms, 0, 60'000));
    }
  }
  return 0;
}

std::unique_ptr<DeformStream> StartReconnectingStream(StreamOpener open,
                                                      DeformClient::StreamCallbacks callbacks,
                                                      const ReconnectPolicy& policy) {
  return std::make_unique<ReconnectingStream>(std::move(open), std::move(callbacks), policy);
}

}  // namespace deform::client::internal
