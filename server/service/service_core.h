// Everything the service's RPCs share: the mesh registry, the worker pool and the open streams.
// The gRPC service class is a thin layer over this object (no gRPC types here).
//
// Ownership: the server owns one ServiceCore; it must outlive every reactor (the server shuts
// down gRPC and then the worker pool before destroying it).
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <unordered_set>

#include "service/mesh_registry.h"
#include "service/service_options.h"
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
  bool Add(Drainable* stream);
  void Remove(Drainable* stream);
  // Calls Drain() on every registered stream; later Add() calls fail.
  void DrainAll();
  int count() const;

 private:
  mutable std::mutex mutex_;
  std::unordered_set<Drainable*> streams_;  // guarded by mutex_
  bool draining_ = false;                   // guarded by mutex_
};

struct ServiceCore {
  explicit ServiceCore(const ServerOptions& options)
      : limits(options.limits), registry(options.limits), pool(options.workers) {}

  const ServiceLimits limits;
  MeshRegistry registry;
  WorkerPool pool;
  ActiveStreams streams;
  std::atomic<std::uint64_t> next_stream_id{1};
  std::atomic<std::uint64_t> next_load_id{1};
};

}  // namespace deform::service
