// Everything the service's RPCs share: who may call (the authenticator), the mesh registry, the
// worker pool and the open streams.
// The gRPC service class is a thin layer over this object (no gRPC types here).
//
// Ownership: the server owns one ServiceCore; it must outlive every reactor (the server shuts
// down gRPC and then the worker pool before destroying it).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <unordered_set>

#include "core/base/cancel_token.h"
#include "service/annotated_mutex.h"
#include "service/identity.h"
#include "service/mesh_registry.h"
#include "service/mesh_store.h"
#include "service/service_metrics.h"
#include "service/service_options.h"
#include "service/thread_annotations.h"
#include "service/upload_watchdog.h"
#include "service/worker_pool.h"

namespace deform::service {

// Something that can be asked to end early because the server is shutting down.
class Drainable {
 public:
  // Ends the stream soon (with UNAVAILABLE). Must not block; must not call back into
  // ActiveStreams (it is called with the ActiveStreams lock held).
  virtual void Drain() = 0;

 protected:
  ~Drainable() = default;
};

// The open Deform streams, so that a shutdown can end them instead of waiting for the clients.
// Thread-safe.
class ActiveStreams {
 public:
  // Registers `stream`; false (not registered) once DrainAll() has been called.
  bool Add(Drainable* stream) DEFORM_EXCLUDES(mutex_);
  void Remove(Drainable* stream) DEFORM_EXCLUDES(mutex_);
  // Calls Drain() on every registered stream; later Add() calls fail.
  void DrainAll() DEFORM_EXCLUDES(mutex_);
  int count() const DEFORM_EXCLUDES(mutex_);

 private:
  mutable Mutex mutex_;
  std::unordered_set<Drainable*> streams_ DEFORM_GUARDED_BY(mutex_);
  bool draining_ DEFORM_GUARDED_BY(mutex_) = false;
};

// Open Deform streams per tenant and in all, against ServiceLimits::tenant_max_streams and
// max_streams. Thread-safe.
class TenantStreamQuota {
 public:
  // A limit <= 0: none (streams are still counted).
  TenantStreamQuota(int max_per_tenant, int max_total)
      : max_per_tenant_(max_per_tenant), max_total_(max_total) {}
  // Counts one more stream of `tenant`; RESOURCE_EXHAUSTED naming the limit when max_total are
  // open already, or max_per_tenant of `tenant`'s. Release() once for every successful Acquire().
  Status Acquire(const std::string& tenant) DEFORM_EXCLUDES(mutex_);
  void Release(const std::string& tenant) DEFORM_EXCLUDES(mutex_);

 private:
  const int max_per_tenant_;
  const int max_total_;
  Mutex mutex_;
  std::map<std::string, int> open_ DEFORM_GUARDED_BY(mutex_);
  int total_ DEFORM_GUARDED_BY(mutex_) = 0;
};

struct ServiceCore {
  explicit ServiceCore(const ServerOptions& options)
      : limits(options.limits),
        registry(options.limits,
                 {WorkerPool::ResolveThreads(options.workers), options.batch_frames,
                  options.parallel_solve_min_factor_bytes, options.float32_factor_min_bytes}),
        pool(options.workers, options.batch_frames),
        uploads(std::chrono::milliseconds(options.limits.upload_idle_timeout_ms),
                std::chrono::milliseconds(options.limits.upload_time_limit_ms)),
        tenant_streams(options.limits.tenant_max_streams, options.limits.max_streams) {}

  const ServiceLimits limits;
  // Who may call (token file, or the single implicit tenant).
  Authenticator auth;
  MeshRegistry registry;
  WorkerPool pool;
  UploadWatchdog uploads;
  ActiveStreams streams;
  TenantStreamQuota tenant_streams;
  // Where loaded meshes are kept across restarts (--store); null: nowhere. Set before serving.
  std::unique_ptr<MeshStore> store;
  // Cancelled when the server shuts down: the parent of every build's token (cancel_token.h).
  CancelToken shutting_down;
  std::atomic<std::uint64_t> next_stream_id{1};
  std::atomic<std::uint64_t> next_load_id{1};
  // Serialised bytes of the notices waiting unwritten in every Deform stream (DeformOutbox).
  std::atomic<std::int64_t> notice_backlog_bytes{0};
  // Counters and histograms of frames, notices, RPCs, builds (service_metrics.h).
  ServiceMetrics metrics;
};

}  // namespace deform::service
