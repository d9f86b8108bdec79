#include "service/load/store_restore.h"

#include <spdlog/spdlog.h>

#include <utility>

#include "service/base/log_text.h"
#include "service/load/load_request.h"
#include "service/load/mesh_loader.h"

namespace deform::service {
namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

StatusOr<std::shared_ptr<const MeshEntry>> RestoreStoredMesh(ServiceContext* context,
                                                             StoredMesh* stored,
                                                             Clock::time_point start) {
  DEFORM_ASSIGN_OR_RETURN(
      LoadJob job, LoadJobFromRequest(stored->header, &stored->mesh_bytes, context->limits()));
  job.name = stored->header.name();
  job.id = stored->id;
  job.start = start;
  job.metrics = &context->metrics();
  job.cancel = &context->shutting_down();
  DEFORM_ASSIGN_OR_RETURN(Admission::MeshSlot reservation,
                          context->admission().ReserveMesh(stored->tenant));
  DEFORM_ASSIGN_OR_RETURN(std::shared_ptr<const MeshEntry> entry,
                          BuildAndRegister(context, std::move(reservation), std::move(job)));
  context->MarkStored(entry->id);
  return entry;
}

Status StoreRestorer::Restore(const std::string& mesh_id, const Identity& caller) {
  const Status building =
      Status::Unavailable("mesh " + mesh_id + " is being built on this server from the store")
          .WithRetryDelay(kRetryDelayMs);
  {
    MutexLock lock(&mutex_);
    if (building_.count(mesh_id) != 0) return building;
    const auto failure = failed_.find(mesh_id);
    if (failure != failed_.end()) {
      if (Clock::now() - failure->second.at < std::chrono::milliseconds(kFailureMemoryMs)) {
        return failure->second.status;
      }
      failed_.erase(failure);
    }
  }
  // Read before building: the tenant the entry names (checked again once the entry is verified).
  const StatusOr<std::string> owner = context_->store()->PeekTenant(mesh_id);
  if (!owner.ok() || !caller.CanAccess(*owner)) return Status::NotFound("no such mesh");
  {
    MutexLock lock(&mutex_);
    if (!building_.insert(mesh_id).second) return building;
  }
  spdlog::info("mesh={} tenant={} not loaded here: building it from the store", mesh_id,
               EscapeForLog(*owner));
  context_->pool().PostBackground([this, mesh_id] { Build(mesh_id); });
  return building;
}

void StoreRestorer::Build(const std::string& mesh_id) {
  const Clock::time_point start = Clock::now();
  StatusOr<StoredMesh> stored = context_->store()->Read(mesh_id);
  Status status = stored.status();
  if (stored.ok()) {
    const std::string tenant = stored->tenant;
    const StatusOr<std::shared_ptr<const MeshEntry>> entry =
        RestoreStoredMesh(context_, &*stored, start);
    status = entry.status();
    if (entry.ok()) {
      spdlog::info("mesh={} tenant={} built from the store in {:.0f} ms", mesh_id,
                   EscapeForLog(tenant), MillisecondsSince(start));
    } else {
      spdlog::error("mesh={} tenant={} not built from the store: {}", mesh_id, EscapeForLog(tenant),
                    status.ToString());
    }
  }
  MutexLock lock(&mutex_);
  building_.erase(mesh_id);
  if (status.ok()) return;
  if (failed_.size() >= kMaxFailures) failed_.clear();
  // A budget's refusal is the caller's to see; anything else (a corrupt or vanished entry, a build
  // that failed) is as if there were no such mesh.
  failed_[mesh_id] = {
      status.code() == StatusCode::kResourceExhausted ? status : Status::NotFound("no such mesh"),
      Clock::now()};
}

}  // namespace deform::service
