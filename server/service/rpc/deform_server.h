// The deformation server: the gRPC server with the DeformService, health checking and
// reflection, over a ServiceContext (registry, worker pool, open streams). Used by deformd and by
// the in-process tests. No gRPC headers here.
//
// Life cycle: construct, optionally Preload(), Start(), then Shutdown() (also done by the
// destructor). Thread safety: Shutdown() may be called from any thread, once or more; the other
// methods from the owning thread.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "core/base/status.h"
#include "core/io/model_input.h"
#include "service/access/identity.h"
#include "service/base/service_options.h"
#include "service/registry/mesh_registry.h"

namespace deform::service {

class ServiceContext;

class DeformServer {
 public:
  explicit DeformServer(const ServerOptions& options);
  ~DeformServer();
  DeformServer(const DeformServer&) = delete;
  DeformServer& operator=(const DeformServer&) = delete;

  // Binds options.listen_address and starts serving, with TLS or plaintext as options.security
  // says (transport_security.h), and GET /metrics on options.metrics_address if given (plain HTTP,
  // loopback unless allow_plaintext: metrics_endpoint.h). FAILED_PRECONDITION if the address cannot
  // be bound, the server was already started, or the transport policy refuses (plaintext on a
  // non-loopback address without allow_plaintext); NOT_FOUND for an unreadable certificate or key
  // file.
  Status Start();
  // The bound port (useful with port 0), or 0 before Start().
  int port() const;
  // The metrics port (options.metrics_address, metrics_endpoint.h) once started, or 0.
  int metrics_port() const;
  // Open connections to the gRPC port (connection_acceptor.h); 0 before Start().
  int open_connections() const;
  // "host:port" with the bound port.
  std::string listening_address() const;

  // Builds and registers a mesh directly (no RPC), on the calling thread, owned by `tenant`; for
  // --preload.
  StatusOr<std::shared_ptr<const MeshEntry>> Preload(
      ModelInput input, const std::string& name,
      const std::string& tenant = Identity::Implicit().tenant);

  // Keeps loaded meshes in the store at `dir` (mesh_store.h) from now on, and first builds every
  // mesh stored there under its id and owner, on the calling thread; before Start(). A corrupt or
  // failing entry is logged and skipped. FAILED_PRECONDITION when the directory cannot be used.
  // `restored` (optional) receives the number of meshes restored. `key_file`: the store's HMAC
  // key (--store-key; mesh_store.h), empty for none; it is also the secret of the mesh keys
  // (mesh_key.h). `shared` (--store-shared): a store the replicas of a cluster share
  // (docs/cluster.md): it needs a key (the replicas must agree on mesh keys), restores nothing at
  // start, and builds a mesh another replica loaded when a call first names it (StoreRestorer).
  Status UseStore(const std::string& dir, int* restored = nullptr, const std::string& key_file = "",
                  bool shared = false);

  // Authenticates calls with the token file at `path` from now on (identity.h); before Start().
  // NOT_FOUND or INVALID_ARGUMENT (naming the line) for a bad file. Without it, every caller is
  // the single implicit tenant.
  Status UseTokenFile(const std::string& path);
  // Reads the token file again (deformd's SIGHUP): new tokens work and removed ones stop working
  // for the next call. On error the old tokens stay and the error is returned (and logged).
  Status ReloadTokens();

  // Another transport over the same context (deformd's HTTP port, rpc/web_server.h): Shutdown()
  // calls `stop` with a grace period after the streams were drained and gRPC has stopped, before
  // the worker pool stops, so that its streams end while the pool still runs. Before Start().
  void AddTransportStop(std::function<void(std::chrono::milliseconds)> stop);

  // Drains: marks the server not serving, ends open Deform streams with UNAVAILABLE, stops
  // accepting calls, waits up to `grace` for calls in progress (then cancels them), stops the
  // other transports (AddTransportStop, a tenth of `grace` each) and the worker pool. Idempotent.
  void Shutdown(std::chrono::milliseconds grace = std::chrono::seconds(5));

  ServiceContext& context();

 private:
  // Starts handing the acceptor's connections to gRPC, refusals counted and logged in a budget.
  void StartAccepting();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace deform::service
