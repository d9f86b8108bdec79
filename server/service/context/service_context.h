// What every handler of the service shares (ServiceContext): who may call (the authenticator),
// admission, the mesh registry and store, the worker pool, the upload watchdog, the open streams
// and their latest frames,
// the metrics, and the shutdown signal. The RPC classes and the stream handlers of both
// transports look things up here; no gRPC types here.
//
// Ownership: the server owns one ServiceContext; it must outlive every handler (the server shuts
// down its transports and then the worker pool before destroying it).
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <unordered_set>

#include "core/base/cancel_token.h"
#include "service/access/admission.h"
#include "service/access/identity.h"
#include "service/access/upload_watchdog.h"
#include "service/base/annotated_mutex.h"
#include "service/base/log_budget.h"
#include "service/base/service_options.h"
#include "service/base/thread_annotations.h"
#include "service/context/latest_frames.h"
#include "service/metrics/service_metrics.h"
#include "service/registry/mesh_key.h"
#include "service/registry/mesh_registry.h"
#include "service/registry/mesh_store.h"
#include "service/workers/worker_pool.h"

namespace deform::service {

// Something that can be asked to end early: because the server is shutting down, or because
// the token it was opened with no longer stands.
class Drainable {
 public:
  // Ends the stream soon (with UNAVAILABLE). Must not block; must not call back into
  // ActiveStreams (it is called with the ActiveStreams lock held).
  virtual void Drain() = 0;
  // Who opened the stream.
  virtual const Identity& caller() const = 0;
  // Ends the stream soon with UNAUTHENTICATED, after a KIND_CREDENTIALS_REVOKED notice. Same
  // rules as Drain().
  virtual void Revoke() = 0;

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
  // Calls Revoke() on every registered stream whose caller `auth` no longer accepts
  // (Authenticator::StillValid); how many.
  int RevokeInvalid(const Authenticator& auth) DEFORM_EXCLUDES(mutex_);
  int count() const DEFORM_EXCLUDES(mutex_);

 private:
  mutable Mutex mutex_;
  std::unordered_set<Drainable*> streams_ DEFORM_GUARDED_BY(mutex_);
  bool draining_ DEFORM_GUARDED_BY(mutex_) = false;
};

// Builds a mesh this server has not loaded from a shared store's entry, in the background
// (load/store_restore.h implements it; the context only knows it is there).
class MeshRestorer {
 public:
  virtual ~MeshRestorer() = default;
  // `mesh_id` is not loaded here: UNAVAILABLE with a retry delay while its build (started now, or
  // earlier) runs; NOT_FOUND when the store holds no entry of it for `caller` or its build
  // failed. Must not block (it runs on the RPC's thread).
  virtual Status Restore(const std::string& mesh_id, const Identity& caller) = 0;
};

// Thread safety: the accessors may be called from any thread; each object they return states its
// own (the set_ methods only before serving).
class ServiceContext {
 public:
  explicit ServiceContext(const ServerOptions& options);
  ServiceContext(const ServiceContext&) = delete;
  ServiceContext& operator=(const ServiceContext&) = delete;

  const ServiceLimits& limits() const { return admission_.limits(); }
  // How meshes are prepared for the workers (the loader's PlanMeshSolve and float32 threshold).
  const SolveSettings& solve_settings() const { return solve_settings_; }
  // Who may call (token file, or the single implicit tenant).
  Authenticator& auth() { return auth_; }
  const Authenticator& auth() const { return auth_; }
  // What may be loaded and held: mesh slots, the memory budget, stream quotas.
  Admission& admission() { return admission_; }
  MeshRegistry& registry() { return registry_; }
  WorkerPool& pool() { return pool_; }
  UploadWatchdog& uploads() { return uploads_; }
  ActiveStreams& streams() { return streams_; }
  // Every open Deform stream's latest solved frame, for the contact queries.
  LatestFrames& latest_frames() { return latest_frames_; }
  // Where loaded meshes are kept across restarts (--store); null: nowhere.
  MeshStore* store() const { return store_.get(); }
  // Before serving only.
  void set_store(std::unique_ptr<MeshStore> store) { store_ = std::move(store); }
  // What names a load's mesh (mesh_key.h): under the store key, or a random secret.
  const MeshKeys& mesh_keys() const { return mesh_keys_; }
  void set_mesh_keys(MeshKeys keys) { mesh_keys_ = std::move(keys); }
  // With a shared store (MeshStore::shared): how meshes not loaded here are built.
  void set_restorer(std::unique_ptr<MeshRestorer> restorer) { restorer_ = std::move(restorer); }

  // The mesh `caller` may use, as MeshRegistry::Find; with a shared store, also what the other
  // replicas did: a mesh another replica unloaded (its entry gone) is unloaded here and
  // NOT_FOUND, and one another replica loaded is built here (MeshRestorer::Restore: UNAVAILABLE
  // with a retry delay meanwhile). Every RPC that names a mesh looks it up here.
  StatusOr<std::shared_ptr<const MeshEntry>> FindMesh(const std::string& mesh_id,
                                                      const Identity& caller)
      DEFORM_EXCLUDES(stored_mutex_);
  // The mesh `id` has an entry in the store (kept at its load, or built from it).
  void MarkStored(const std::string& id) DEFORM_EXCLUDES(stored_mutex_);
  // Cancelled when the server shuts down: the parent of every build's token (cancel_token.h).
  CancelToken& shutting_down() { return shutting_down_; }
  // Ids for log lines: each stream's and each load's, counting from 1.
  std::uint64_t NextStreamId() { return next_stream_id_.fetch_add(1); }
  std::uint64_t NextLoadId() { return next_load_id_.fetch_add(1); }
  // Serialized bytes of the notices waiting unwritten in every Deform stream (DeformOutbox).
  std::atomic<std::int64_t>& notice_backlog_bytes() { return notice_backlog_bytes_; }
  // Counters and histograms of frames, notices, RPCs, builds (service_metrics.h).
  ServiceMetrics& metrics() { return metrics_; }
  // A refusal any peer can cause at will: counted in deformd_refused_total{reason}, and whether
  // its log line may be written (a burst of kRefusalLineBurst lines per reason, then
  // kRefusalLinesPerSecond); *held_back receives that reason's lines not written since the last.
  static constexpr double kRefusalLinesPerSecond = 1;
  static constexpr double kRefusalLineBurst = 10;
  bool CountRefusal(ServiceMetrics::Refusal reason, std::uint64_t* held_back);

 private:
  const SolveSettings solve_settings_;
  Authenticator auth_;
  Admission admission_;
  MeshRegistry registry_;
  WorkerPool pool_;
  UploadWatchdog uploads_;
  ActiveStreams streams_;
  LatestFrames latest_frames_;
  std::unique_ptr<MeshStore> store_;
  MeshKeys mesh_keys_;
  std::unique_ptr<MeshRestorer> restorer_;
  mutable Mutex stored_mutex_;
  std::unordered_set<std::string> stored_ids_ DEFORM_GUARDED_BY(stored_mutex_);
  CancelToken shutting_down_;
  std::atomic<std::uint64_t> next_stream_id_{1};
  std::atomic<std::uint64_t> next_load_id_{1};
  std::atomic<std::int64_t> notice_backlog_bytes_{0};
  ServiceMetrics metrics_;
  std::array<LogBudget, ServiceMetrics::kRefusals> refusal_lines_{
      {LogBudget(kRefusalLinesPerSecond, kRefusalLineBurst),
       LogBudget(kRefusalLinesPerSecond, kRefusalLineBurst),
       LogBudget(kRefusalLinesPerSecond, kRefusalLineBurst),
       LogBudget(kRefusalLinesPerSecond, kRefusalLineBurst),
       LogBudget(kRefusalLinesPerSecond, kRefusalLineBurst),
       LogBudget(kRefusalLinesPerSecond, kRefusalLineBurst),
       LogBudget(kRefusalLinesPerSecond, kRefusalLineBurst)}};
};

}  // namespace deform::service
