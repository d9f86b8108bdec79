#include "service/context/service_context.h"

#include <spdlog/spdlog.h>

#include "service/base/log_text.h"

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

int ActiveStreams::RevokeInvalid(const Authenticator& auth) {
  MutexLock lock(&mutex_);
  int revoked = 0;
  for (Drainable* stream : streams_) {
    if (auth.StillValid(stream->caller())) continue;
    stream->Revoke();
    ++revoked;
  }
  return revoked;
}

int ActiveStreams::count() const {
  MutexLock lock(&mutex_);
  return static_cast<int>(streams_.size());
}

ServiceContext::ServiceContext(const ServerOptions& options)
    : solve_settings_{WorkerPool::ResolveThreads(options.workers), options.batch_frames,
                      options.parallel_solve_min_factor_bytes, options.float32_factor_min_bytes},
      admission_(options.limits),
      registry_(&admission_),
      pool_(options.workers, options.batch_frames),
      uploads_(std::chrono::milliseconds(options.limits.upload_idle_timeout_ms),
               std::chrono::milliseconds(options.limits.upload_time_limit_ms)) {
  InstallEscapingDefaultLogger();  // every line safe, in-process servers included (log_text.h)
}

StatusOr<std::shared_ptr<const MeshEntry>> ServiceContext::FindMesh(const std::string& mesh_id,
                                                                    const Identity& caller) {
  StatusOr<std::shared_ptr<const MeshEntry>> entry = registry_.Find(mesh_id, caller);
  if (store_ == nullptr || !store_->shared()) return entry;
  if (entry.ok()) {
    bool stored;
    {
      MutexLock lock(&stored_mutex_);
      stored = stored_ids_.count(mesh_id) != 0;
    }
    if (!stored || store_->Contains(mesh_id)) return entry;
    // Unloaded by another replica: its open streams here run on (they hold the model).
    spdlog::info("mesh={} unloaded on another replica (its store entry is gone): unloading it",
                 mesh_id);
    (void)registry_.Unload(mesh_id);
    {
      MutexLock lock(&stored_mutex_);
      stored_ids_.erase(mesh_id);
    }
    return registry_.Find(mesh_id, caller);  // NOT_FOUND, as any unknown id
  }
  if (entry.status().code() != StatusCode::kNotFound || restorer_ == nullptr) return entry;
  const Status restoring = restorer_->Restore(mesh_id, caller);
  if (restoring.code() == StatusCode::kNotFound) return entry;  // the registry's own message
  return restoring;
}

void ServiceContext::MarkStored(const std::string& id) {
  MutexLock lock(&stored_mutex_);
  stored_ids_.insert(id);
}

bool ServiceContext::CountRefusal(ServiceMetrics::Refusal reason, std::uint64_t* held_back) {
  metrics_.Refused(reason);
  const int index = static_cast<int>(reason);
  if (index < 0 || index >= ServiceMetrics::kRefusals) return false;
  return refusal_lines_[index].Take(held_back);
}

}  // namespace deform::service
