#include "service/context/latest_frames.h"

#include <algorithm>
#include <utility>

namespace deform::service {

LatestFrame::LatestFrame(std::string tenant, std::string mesh_id, int vertices)
    : tenant_(std::move(tenant)), mesh_id_(std::move(mesh_id)), vertices_(vertices) {
  MutexLock lock(&mutex_);
  xyz_.assign(3 * static_cast<std::size_t>(vertices), 0.0);
}

void LatestFrame::Publish(const double* xyz, std::uint64_t sequence) {
  MutexLock lock(&mutex_);
  std::copy(xyz, xyz + xyz_.size(), xyz_.begin());
  sequence_ = sequence;
  frame_number_.store(frame_number_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
}

bool LatestFrame::CopyIfNewer(std::uint64_t have, double* xyz, std::uint64_t* number,
                              std::uint64_t* sequence) const {
  if (frame_number() <= have) return false;
  MutexLock lock(&mutex_);
  std::copy(xyz_.begin(), xyz_.end(), xyz);
  *number = frame_number_.load(std::memory_order_relaxed);
  *sequence = sequence_;
  return true;
}

void LatestFrames::Add(std::uint64_t stream_id, std::shared_ptr<LatestFrame> frame) {
  MutexLock lock(&mutex_);
  frames_[stream_id] = std::move(frame);
}

void LatestFrames::Remove(std::uint64_t stream_id) {
  std::shared_ptr<LatestFrame> removed;  // freed outside the lock
  MutexLock lock(&mutex_);
  const auto it = frames_.find(stream_id);
  if (it == frames_.end()) return;
  removed = std::move(it->second);
  frames_.erase(it);
}

StatusOr<std::shared_ptr<const LatestFrame>> LatestFrames::Find(std::uint64_t stream_id,
                                                                const Identity& caller) const {
  MutexLock lock(&mutex_);
  const auto it = frames_.find(stream_id);
  if (it == frames_.end() || !caller.CanAccess(it->second->tenant())) {
    return Status::NotFound("no open Deform stream " + std::to_string(stream_id));
  }
  return std::shared_ptr<const LatestFrame>(it->second);
}

int LatestFrames::count() const {
  MutexLock lock(&mutex_);
  return static_cast<int>(frames_.size());
}

}  // namespace deform::service
