#include "service/service_core.h"

namespace deform::service {

bool ActiveStreams::Add(Drainable* stream) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (draining_) return false;
  streams_.insert(stream);
  return true;
}

void ActiveStreams::Remove(Drainable* stream) {
  std::lock_guard<std::mutex> lock(mutex_);
  streams_.erase(stream);
}

void ActiveStreams::DrainAll() {
  std::lock_guard<std::mutex> lock(mutex_);
  draining_ = true;
  for (Drainable* stream : streams_) stream->Drain();
}

int ActiveStreams::count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(streams_.size());
}

}  // namespace deform::service
