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

Status TenantStreamQuota::Acquire(const std::string& tenant) {
  MutexLock lock(&mutex_);
  if (max_total_ > 0 && total_ >= max_total_) {
    return Status::ResourceExhausted("server stream limit reached (--max-streams): " +
                                     std::to_string(total_) + " streams open, of at most " +
                                     std::to_string(max_total_));
  }
  int& open = open_[tenant];
  if (max_per_tenant_ > 0 && open >= max_per_tenant_) {
    return Status::ResourceExhausted("tenant stream limit reached (--tenant-max-streams): " +
                                     std::to_string(open) + " streams open, of at most " +
                                     std::to_string(max_per_tenant_) + " per tenant");
  }
  ++open;
  ++total_;
  return Status::Ok();
}

void TenantStreamQuota::Release(const std::string& tenant) {
  MutexLock lock(&mutex_);
  const auto it = open_.find(tenant);
  if (it == open_.end()) return;
  --total_;
  if (--it->second == 0) open_.erase(it);
}

}  // namespace deform::service
