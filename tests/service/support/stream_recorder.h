// Records what a Deform stream delivers (frames, notices, the final status), thread-safely, and
// lets a test wait for conditions with generous timeouts instead of sleeping.
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "deform_client.h"

namespace deform::test_support {

// Long enough for a loaded 2-core machine; tests only wait this long when something is broken.
constexpr std::chrono::seconds kWaitTimeout{60};

struct RecordedEvent {
  bool is_frame = false;
  v1::DeformFrame frame;  // when is_frame (positions kept only if the recorder keeps them)
  v1::Notice notice;      // otherwise
};

class StreamRecorder {
 public:
  explicit StreamRecorder(bool keep_positions = false) : keep_positions_(keep_positions) {}

  client::DeformClient::StreamCallbacks Callbacks() {
    client::DeformClient::StreamCallbacks callbacks;
    callbacks.on_frame = [this](const v1::DeformFrame& frame) {
      std::lock_guard<std::mutex> lock(mutex_);
      RecordedEvent& event = events_.emplace_back();
      event.is_frame = true;
      event.frame = frame;
      if (!keep_positions_) event.frame.clear_positions();
      last_frame_ = frame;
      ++frames_;
      changed_.notify_all();
    };
    callbacks.on_notice = [this](const v1::Notice& notice) {
      std::lock_guard<std::mutex> lock(mutex_);
      RecordedEvent& event = events_.emplace_back();
      event.notice = notice;
      changed_.notify_all();
    };
    callbacks.on_done = [this](const grpc::Status& status) {
      std::lock_guard<std::mutex> lock(mutex_);
      status_ = status;
      changed_.notify_all();
    };
    return callbacks;
  }

  // Waits until `predicate` (called with the lock held) is true; false on timeout.
  bool WaitUntil(const std::function<bool()>& predicate,
                 std::chrono::milliseconds timeout = kWaitTimeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, timeout, predicate);
  }
  bool WaitForFrames(std::int64_t count) {
    return WaitUntil([&] { return frames_ >= count; });
  }
  bool WaitForFrameWithSequence(std::uint64_t sequence) {
    return WaitUntil([&] { return frames_ > 0 && last_frame_.sequence() >= sequence; });
  }
  bool WaitForNotice(v1::Notice::Kind kind) {
    return WaitUntil([&] { return FindNoticeLocked(kind).has_value(); });
  }
  bool WaitForDone() {
    return WaitUntil([&] { return status_.has_value(); });
  }

  std::int64_t frames() {
    std::lock_guard<std::mutex> lock(mutex_);
    return frames_;
  }
  v1::DeformFrame last_frame() {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_frame_;
  }
  // The events so far; only inside a WaitUntil predicate (the lock is held there).
  const std::vector<RecordedEvent>& EventsLocked() const { return events_; }
  std::vector<RecordedEvent> events() {
    std::lock_guard<std::mutex> lock(mutex_);
    return events_;
  }
  std::optional<v1::Notice> FindNotice(v1::Notice::Kind kind) {
    std::lock_guard<std::mutex> lock(mutex_);
    return FindNoticeLocked(kind);
  }
  std::optional<grpc::Status> status() {
    std::lock_guard<std::mutex> lock(mutex_);
    return status_;
  }

 private:
  std::optional<v1::Notice> FindNoticeLocked(v1::Notice::Kind kind) const {
    for (const RecordedEvent& event : events_) {
      if (!event.is_frame && event.notice.kind() == kind) return event.notice;
    }
    return std::nullopt;
  }

  const bool keep_positions_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<RecordedEvent> events_;
  v1::DeformFrame last_frame_;
  std::int64_t frames_ = 0;
  std::optional<grpc::Status> status_;
};

// A pose of the knee phantom (hip and knee flexion, degrees).
inline v1::PoseUpdate KneePose(std::uint64_t sequence, double knee_degrees,
                               double hip_degrees = 0) {
  v1::PoseUpdate pose;
  pose.set_sequence(sequence);
  pose.set_client_timestamp_ns(client::MonotonicNanos());
  v1::JointAngle* knee = pose.add_angles();
  knee->set_joint("knee");
  knee->set_axis("flexion");
  knee->set_degrees(knee_degrees);
  if (hip_degrees != 0) {
    v1::JointAngle* hip = pose.add_angles();
    hip->set_joint("hip");
    hip->set_axis("flexion");
    hip->set_degrees(hip_degrees);
  }
  return pose;
}

// Sends a knee pose every `period` on `stream` from its own thread until destroyed: a client that
// keeps streaming while a test does something else.
class PosePacer {
 public:
  PosePacer(client::DeformStream* stream, std::chrono::milliseconds period)
      : thread_([this, stream, period] {
          std::uint64_t sequence = 0;
          while (!stop_.load()) {
            ++sequence;
            if (!stream->SendPose(KneePose(sequence, static_cast<double>(sequence % 90)))) break;
            std::this_thread::sleep_for(period);
          }
        }) {}
  ~PosePacer() {
    stop_.store(true);
    thread_.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace deform::test_support
