// Ends LoadMesh uploads that stall or take too long, so that a client that never finishes its
// upload cannot hold a mesh slot and its bytes of the memory budget forever.
//
// An upload is watched from its header to its last byte: it expires when no chunk has arrived for
// `idle_timeout` (ServiceLimits::upload_idle_timeout_ms) or when it has lasted `time_limit`
// (ServiceLimits::upload_time_limit_ms) in all. The watchdog then calls ExpireUpload() on it,
// once, from its own thread; the target answers its client (DEADLINE_EXCEEDED) and releases its
// slot. A zero duration disables that limit.
//
// Ownership: the watchdog keeps weak references only; a target that has gone away is forgotten.
// Thread safety: every method may be called from any thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <thread>

#include "service/base/annotated_mutex.h"
#include "service/base/thread_annotations.h"

namespace deform::service {

class ExpiringUpload {
 public:
  // Called at most once, on the watchdog's thread, never with the watchdog's lock held. `why`
  // names the limit ("no upload data for 30 s (--upload-idle-timeout-s)").
  virtual void ExpireUpload(const std::string& why) = 0;

 protected:
  ~ExpiringUpload() = default;
};

class UploadWatchdog {
 public:
  using Clock = std::chrono::steady_clock;
  UploadWatchdog(std::chrono::milliseconds idle_timeout, std::chrono::milliseconds time_limit);
  ~UploadWatchdog();  // stops the thread
  UploadWatchdog(const UploadWatchdog&) = delete;
  UploadWatchdog& operator=(const UploadWatchdog&) = delete;

  // Starts watching `upload`; the id for Touch and Forget.
  std::uint64_t Watch(std::weak_ptr<ExpiringUpload> upload) DEFORM_EXCLUDES(mutex_);
  // Data arrived: the idle time starts again.
  void Touch(std::uint64_t id) DEFORM_EXCLUDES(mutex_);
  // The upload is complete or ended: no longer watched.
  void Forget(std::uint64_t id) DEFORM_EXCLUDES(mutex_);

 private:
  struct Watched {
    std::weak_ptr<ExpiringUpload> upload;
    Clock::time_point started;
    Clock::time_point last_data;
  };
  void Run() DEFORM_EXCLUDES(mutex_);

  const std::chrono::milliseconds idle_timeout_;
  const std::chrono::milliseconds time_limit_;
  Mutex mutex_;
  CondVar wake_;
  std::map<std::uint64_t, Watched> watched_ DEFORM_GUARDED_BY(mutex_);
  std::uint64_t next_id_ DEFORM_GUARDED_BY(mutex_) = 1;
  bool stopping_ DEFORM_GUARDED_BY(mutex_) = false;
  std::thread thread_;  // last: started once the members above exist
};

}  // namespace deform::service
