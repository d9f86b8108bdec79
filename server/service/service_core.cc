#include "service/service_core.h"

namespace deform::service {

bool ActiveStreams::Add(Drainable* stream) {
  MutexLock lock(&mutex_);
  if (draining_) return false;
  streams_.insert(stream);
  return true;
}

void ActiveStreams::Remove(Drainable* stream) {
  MutexLock lock(&mutex_);
  streams_.erase(stream);
}

void ActiveStreams::DrainAll() {
  MutexLock lock(&mutex_);
  draining_ = true;
  for (Drainable* stream : streams_) stream->Drain();
}

int ActiveStreams::count() const {
  MutexLock lock(&mutex_);
  return static_cast<int>(streams_.size());
}

}  // namespace deform::service
