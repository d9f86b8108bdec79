#include "service/access/upload_watchdog.h"

#include <algorithm>
#include <utility>
#include <vector>

namespace deform::service {
namespace {

std::string Seconds(std::chrono::milliseconds duration) {
  const double seconds = std::chrono::duration<double>(duration).count();
  std::string text = std::to_string(seconds);
  text.erase(text.find_last_not_of('0') + 1);
  if (!text.empty() && text.back() == '.') text.pop_back();
  return text + " s";
}

}  // namespace

UploadWatchdog::UploadWatchdog(std::chrono::milliseconds idle_timeout,
                               std::chrono::milliseconds time_limit)
    : idle_timeout_(idle_timeout), time_limit_(time_limit), thread_([this] { Run(); }) {}

UploadWatchdog::~UploadWatchdog() {
  {
    MutexLock lock(&mutex_);
    stopping_ = true;
  }
  wake_.NotifyAll();
  thread_.join();
}

std::uint64_t UploadWatchdog::Watch(std::weak_ptr<ExpiringUpload> upload) {
  MutexLock lock(&mutex_);
  const Clock::time_point now = Clock::now();
  const std::uint64_t id = next_id_++;
  watched_.emplace(id, Watched{std::move(upload), now, now});
  return id;
}

void UploadWatchdog::Touch(std::uint64_t id) {
  MutexLock lock(&mutex_);
  const auto it = watched_.find(id);
  if (it != watched_.end()) it->second.last_data = Clock::now();
}

void UploadWatchdog::Forget(std::uint64_t id) {
  MutexLock lock(&mutex_);
  watched_.erase(id);
}

void UploadWatchdog::Run() {
  // Checked at a tenth of the shorter limit (at most once a second, at least every 10 ms).
  std::chrono::milliseconds shortest = std::chrono::milliseconds(10'000);
  for (const auto limit : {idle_timeout_, time_limit_}) {
    if (limit.count() > 0) shortest = std::min(shortest, limit);
  }
  const auto period =
      std::clamp(shortest / 10, std::chrono::milliseconds(10), std::chrono::milliseconds(1000));
  MutexLock lock(&mutex_);
  while (!stopping_) {
    wake_.WaitFor(&mutex_, period);
    const Clock::time_point now = Clock::now();
    std::vector<std::pair<std::shared_ptr<ExpiringUpload>, std::string>> expired;
    for (auto it = watched_.begin(); it != watched_.end();) {
      std::string why;
      if (idle_timeout_.count() > 0 && now - it->second.last_data >= idle_timeout_) {
        why = "no upload data for " + Seconds(idle_timeout_) + " (--upload-idle-timeout-s)";
      } else if (time_limit_.count() > 0 && now - it->second.started >= time_limit_) {
        why = "the upload took longer than " + Seconds(time_limit_) + " (--upload-time-limit-s)";
      }
      std::shared_ptr<ExpiringUpload> upload = it->second.upload.lock();
      if (upload == nullptr || !why.empty()) {
        if (upload != nullptr) expired.emplace_back(std::move(upload), std::move(why));
        it = watched_.erase(it);
      } else {
        ++it;
      }
    }
    if (expired.empty()) continue;
    lock.Unlock();
    for (auto& [upload, why] : expired) upload->ExpireUpload(why);
    expired.clear();  // the last references may go here, outside the lock
    lock.Lock();
  }
}

}  // namespace deform::service
