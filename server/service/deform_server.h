// The deformation server: the gRPC server with the DeformService, health checking and
// reflection, over a ServiceCore (registry, worker pool, open streams). Used by deformd and by the
// in-process tests. No gRPC headers here.
//
// Life cycle: construct, optionally Preload(), Start(), then Shutdown() (also done by the
// destructor). Thread safety: Shutdown() may be called from any thread, once or more; the other
// methods from the owning thread.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "core/base/status.h"
#include "core/io/model_input.h"
#include "service/mesh_registry.h"
#include "service/service_options.h"

namespace deform::service {

struct ServiceCore;

class DeformServer {
 public:
  explicit DeformServer(const ServerOptions& options);
  ~DeformServer();
  DeformServer(const DeformServer&) = delete;
  DeformServer& operator=(const DeformServer&) = delete;

  // Binds options.listen_address and starts serving. FAILED_PRECONDITION if the address cannot
  // be bound or the server was already started.
  Status Start();
  // The bound port (useful with port 0), or 0 before Start().
  int port() const;
  // "host:port" with the bound port.
  std::string listening_address() const;

  // Builds and registers a mesh directly (no RPC), on the calling thread; for --preload.
  StatusOr<std::shared_ptr<const MeshEntry>> Preload(ModelInput input, const std::string& name);

  // Drains: marks the server not serving, ends open Deform streams with UNAVAILABLE, stops
  // accepting calls, waits up to `grace` for calls in progress (then cancels them), and stops the
  // worker pool. Idempotent.
  void Shutdown(std::chrono::milliseconds grace = std::chrono::seconds(5));

  ServiceCore& core();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace deform::service
