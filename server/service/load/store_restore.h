// Meshes built again from store entries (registry/mesh_store.h), under their ids and owners: all of
// an exclusive store's at start-up (RestoreStoredMesh, one by one), and a shared store's on demand
// (StoreRestorer: the first call naming a mesh another replica loaded starts its build here).
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "core/base/status.h"
#include "service/access/identity.h"
#include "service/base/annotated_mutex.h"
#include "service/base/thread_annotations.h"
#include "service/context/service_context.h"
#include "service/registry/mesh_store.h"

namespace deform::service {

// Builds `stored` under its id and owner and registers it (`start` is when its restore began).
// Runs as long as the build takes: a worker's thread, or start-up.
StatusOr<std::shared_ptr<const MeshEntry>> RestoreStoredMesh(
    ServiceContext* context, StoredMesh* stored, std::chrono::steady_clock::time_point start);

// MeshRestorer for a shared store. While a mesh builds, every call naming it gets UNAVAILABLE
// with a retry delay of kRetryDelayMs (google.rpc.RetryInfo), so a client retries (the client
// libraries do: docs/cluster.md, "Failover"); a mesh is built once however many calls ask. A build
// that failed (corrupt entry, budget) is answered NOT_FOUND, or the budget's RESOURCE_EXHAUSTED,
// for kFailureMemoryMs without building again.
class StoreRestorer final : public MeshRestorer {
 public:
  static constexpr int kRetryDelayMs = 100;
  static constexpr int kFailureMemoryMs = 5000;

  // `context` (with a store) must outlive the restorer and its builds (the context's pool runs
  // them; the server stops the pool first).
  explicit StoreRestorer(ServiceContext* context) : context_(context) {}

  Status Restore(const std::string& mesh_id, const Identity& caller) override
      DEFORM_EXCLUDES(mutex_);

 private:
  struct Failure {
    Status status;
    std::chrono::steady_clock::time_point at;
  };
  void Build(const std::string& mesh_id) DEFORM_EXCLUDES(mutex_);  // on a worker
  static constexpr std::size_t kMaxFailures = 1024;

  ServiceContext* const context_;
  Mutex mutex_;
  std::unordered_set<std::string> building_ DEFORM_GUARDED_BY(mutex_);
  std::unordered_map<std::string, Failure> failed_ DEFORM_GUARDED_BY(mutex_);
};

}  // namespace deform::service
