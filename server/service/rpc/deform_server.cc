#include "service/rpc/deform_server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <ctime>
#include <thread>
#include <vector>

#include "health.pb.h"
#include "service/base/annotated_mutex.h"
#include "service/base/listen_address.h"
#include "service/base/log_budget.h"
#include "service/base/log_text.h"
#include "service/context/service_context.h"
#include "service/load/load_request.h"
#include "service/load/mesh_loader.h"
#include "service/load/store_restore.h"
#include "service/metrics/rpc_metrics_interceptor.h"
#include "service/registry/mesh_store.h"
#include "service/rpc/deform_service.h"
#include "service/rpc/metrics_endpoint.h"
#include "service/transport/connection_acceptor.h"
#include "service/transport/loopback_port_guard.h"
#include "service/transport/server_certificate.h"
#include "service/transport/transport_security.h"
#include "service/workers/cpu_budget.h"

namespace deform::service {
namespace {

// Keepalive pings, an idle limit and a handshake deadline. (The port itself is deformd's:
// ConnectionAcceptor binds it without SO_REUSEPORT, so no second server can share it.)
void ApplyConnectionOptions(const ConnectionOptions& options, grpc::ServerBuilder* builder) {
  builder->AddChannelArgument(GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS, options.handshake_timeout_ms);
  builder->AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, options.keepalive_time_ms);
  builder->AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, options.keepalive_timeout_ms);
  builder->AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  builder->AddChannelArgument(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);
  builder->AddChannelArgument(GRPC_ARG_MAX_CONNECTION_IDLE_MS, options.max_connection_idle_ms);
  builder->AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS,
                              options.min_client_ping_interval_ms);
}

// The metrics page: the gauges from the service's state now, then everything serialized.
std::string RenderMetrics(ServiceContext* context) {
  ServiceMetrics::Gauges gauges;
  gauges.streams_open = context->streams().count();
  gauges.meshes_loaded = context->registry().mesh_count();
  gauges.loads_in_progress = context->admission().loads_in_progress();
  gauges.memory_used_bytes = context->admission().memory_bytes_used();
  gauges.memory_reserved_bytes = context->admission().memory_bytes_reserved();
  gauges.memory_streams_bytes = context->admission().memory_bytes_streams();
  gauges.memory_budget_bytes = context->limits().max_memory_bytes;
  gauges.notice_backlog_bytes = context->notice_backlog_bytes().load(std::memory_order_relaxed);
  for (const auto& entry : context->registry().List()) {
    gauges.mesh_streams.emplace_back(entry->id,
                                     entry->open_streams.load(std::memory_order_relaxed));
  }
  context->metrics().SetGauges(gauges);
  return context->metrics().Serialize();
}

}  // namespace

struct DeformServer::Impl {
  explicit Impl(const ServerOptions& server_options)
      : options(server_options), context(server_options), service(&context) {}

  const ServerOptions options;
  ServiceContext context;
  DeformServiceImpl service;
  std::unique_ptr<grpc::Server> server;
  // Accepts the gRPC port's connections and hands them to `server` (connection_acceptor.h).
  std::unique_ptr<ConnectionAcceptor> acceptor;
  std::unique_ptr<grpc::experimental::ExternalConnectionAcceptor> handoff;
  std::unique_ptr<MetricsEndpoint> metrics;  // null without options.metrics_address
  int port = 0;
  LoopbackPortGuard port_guard;  // the other loopback family's address on `port`
  std::vector<std::function<void(std::chrono::milliseconds)>> transport_stops;
  Mutex shutdown_mutex;  // serializes Shutdown()
  bool shut_down DEFORM_GUARDED_BY(shutdown_mutex) = false;
};

DeformServer::DeformServer(const ServerOptions& options) : impl_(std::make_unique<Impl>(options)) {}

DeformServer::~DeformServer() { Shutdown(); }

Status DeformServer::Start() {
  if (impl_->server != nullptr) return Status::FailedPrecondition("the server is already started");
  grpc::EnableDefaultHealthCheckService(true);
  // Reflection describes only services whose descriptors are linked in (grpc/grpc#36665): touching
  // the health proto's descriptor keeps it, so reflection lists grpc.health.v1.Health.
  (void)grpc::health::v1::HealthCheckRequest::descriptor();
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  std::string transport;
  ServerCertificate certificate;
  DEFORM_ASSIGN_OR_RETURN(
      std::shared_ptr<grpc::ServerCredentials> credentials,
      MakeServerCredentials(impl_->options.security, impl_->options.listen_address, &transport,
                            &certificate));
  // A fixed port: the other loopback family's address first (loopback_port_guard.h). No valid
  // port (-1): ConnectionAcceptor::Listen refuses the address as it is.
  const std::string& address = impl_->options.listen_address;
  const ListenHostAndPort split = SplitListenAddress(address);
  const int fixed_port = ListenPort(split);
  std::string bind_address = address;
  if (fixed_port > 0) {
    auto guard = LoopbackPortGuard::Hold(address, fixed_port);
    if (!guard.ok()) return guard.status();
    impl_->port_guard = std::move(*guard);
  } else if (const int picked = fixed_port == 0
                                    ? LoopbackPortGuard::PickFreePort(address, &impl_->port_guard)
                                    : 0) {
    // Port 0 on a loopback address: a port free on both families, so the guard cannot fail.
    bind_address = std::string(split.host) + ":" + std::to_string(picked);
  }
  ConnectionLimits limits;
  limits.max_connections = impl_->options.connections.max_connections;
  limits.max_connections_per_address = impl_->options.connections.max_connections_per_address;
  DEFORM_ASSIGN_OR_RETURN(impl_->acceptor, ConnectionAcceptor::Listen(bind_address, limits));
  impl_->port = impl_->acceptor->port();
  grpc::ServerBuilder builder;
  impl_->handoff = builder.experimental().AddExternalConnectionAcceptor(
      grpc::ServerBuilder::experimental_type::ExternalConnectionType::FROM_FD, credentials);
  builder.RegisterService(&impl_->service);
  builder.SetMaxReceiveMessageSize(impl_->options.max_message_bytes);
  builder.SetMaxSendMessageSize(impl_->options.max_message_bytes);
  ApplyConnectionOptions(impl_->options.connections, &builder);
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> interceptors;
  interceptors.push_back(std::make_unique<RpcMetricsInterceptorFactory>(&impl_->context.metrics()));
  builder.experimental().SetInterceptorCreators(std::move(interceptors));
  if (!impl_->options.metrics_address.empty()) {
    ServiceContext* context = &impl_->context;
    DEFORM_ASSIGN_OR_RETURN(
        impl_->metrics, MetricsEndpoint::Start(
                            impl_->options.metrics_address, impl_->options.security.allow_plaintext,
                            &context->auth(), [context] { return RenderMetrics(context); },
                            [context](std::uint64_t* held_back) {
                              return context->CountRefusal(ServiceMetrics::Refusal::kMetricsScrape,
                                                           held_back);
                            }));
  }
  impl_->server = builder.BuildAndStart();
  if (impl_->server == nullptr) {
    impl_->acceptor.reset();
    impl_->metrics.reset();
    impl_->port_guard = LoopbackPortGuard();
    return Status::FailedPrecondition("cannot listen on '" + impl_->options.listen_address + "'");
  }
  if (impl_->port_guard.held().empty()) {  // the kernel's port: the other family's address now
    auto guard = LoopbackPortGuard::Hold(address, impl_->port);
    if (!guard.ok()) {
      impl_->server->Shutdown();
      impl_->server.reset();
      impl_->metrics.reset();
      return guard.status();
    }
    impl_->port_guard = std::move(*guard);
  }
  if (grpc::HealthCheckServiceInterface* health = impl_->server->GetHealthCheckService()) {
    health->SetServingStatus(v1::DeformService::service_full_name(), true);
  }
  StartAccepting();
  if (impl_->options.workers <= 0) {
    // --workers 0: say what sized the pool (cpu_budget.h), the quota of a container included.
    const CpuBudget budget = ReadCpuBudget();
    spdlog::info("--workers 0: {} CPUs in the affinity mask, cgroup CPU quota {}",
                 budget.affinity_cpus,
                 budget.quota ? fmt::format("{:.2f} CPUs", *budget.quota) : std::string("none"));
  }
  spdlog::info("listening on {} ({}) with {} workers, at most {} connections ({} per address)",
               listening_address(), transport, impl_->context.pool().size(),
               impl_->acceptor->limits().max_connections,
               impl_->acceptor->limits().max_connections_per_address);
  if (!impl_->options.security.cert_file.empty()) {
    const std::string& path = impl_->options.security.cert_file;
    impl_->context.metrics().SetCertificateExpiry(certificate.not_after);
    spdlog::info("TLS certificate '{}' valid until {}", EscapeForLog(path),
                 FormatUtc(certificate.not_after));
    for (const std::string& warning : CertificateWarnings(
             certificate, impl_->options.listen_address, std::time(nullptr), path)) {
      spdlog::warn("{}", EscapeControlBytes(warning));
    }
  }
  if (!impl_->context.auth().uses_tokens()) {
    spdlog::warn(
        "no token file: every caller is the single implicit tenant '{}' and sees every "
        "mesh (give --token-file for per-client tokens)",
        Identity::Implicit().tenant);
  }
  return Status::Ok();
}

void DeformServer::StartAccepting() {
  grpc::experimental::ExternalConnectionAcceptor* handoff = impl_->handoff.get();
  ServiceContext* context = &impl_->context;
  const ConnectionLimits limits = impl_->acceptor->limits();
  impl_->acceptor->Start(
      [handoff](int listener_fd, int fd) {
        grpc::experimental::ExternalConnectionAcceptor::NewConnectionParameters connection;
        connection.listener_fd = listener_fd;
        connection.fd = fd;
        handoff->HandleNewConnection(&connection);
      },
      [context, limits](ConnectionAcceptor::Refusal reason, const std::string& peer) {
        std::uint64_t held_back = 0;
        const bool no_descriptors = reason == ConnectionAcceptor::Refusal::kNoDescriptors;
        if (!context->CountRefusal(no_descriptors ? ServiceMetrics::Refusal::kNoDescriptors
                                                  : ServiceMetrics::Refusal::kGrpcConnectionLimit,
                                   &held_back)) {
          return;
        }
        switch (reason) {
          case ConnectionAcceptor::Refusal::kAll:
            spdlog::warn(
                "connection from {} refused: {} connections open (the limit, "
                "--max-connections){}",
                peer, limits.max_connections, HeldBackNote(held_back));
            break;
          case ConnectionAcceptor::Refusal::kPerAddress:
            spdlog::warn(
                "connection from {} refused: {} connections open from that address (the "
                "limit, --max-connections-per-address){}",
                peer, limits.max_connections_per_address, HeldBackNote(held_back));
            break;
          case ConnectionAcceptor::Refusal::kNoDescriptors:
            spdlog::error(
                "out of open files: a waiting connection was closed unserved; accepting "
                "again shortly (raise the open-files limit, or lower "
                "--max-connections){}",
                HeldBackNote(held_back));
            break;
        }
      });
}

Status DeformServer::UseStore(const std::string& dir, int* restored, const std::string& key_file,
                              bool shared) {
  if (shared && key_file.empty()) {
    return Status::FailedPrecondition(
        "--store-shared needs --store-key: the replicas must share the key that names meshes "
        "and seals their entries");
  }
  DEFORM_ASSIGN_OR_RETURN(std::unique_ptr<MeshStore> store, MeshStore::Open(dir, key_file, shared));
  if (key_file.empty()) {
    spdlog::warn(
        "store: no --store-key: entries are checksummed, not authenticated (whoever "
        "can write '{}' can change a mesh's owner)",
        EscapeForLog(dir));
  }
  ServiceContext& context = impl_->context;
  if (!store->key().empty()) context.set_mesh_keys(MeshKeys(store->key()));
  int count = 0;
  if (shared) {
    spdlog::info("store: '{}' shared with other replicas: meshes are built when first named",
                 EscapeForLog(dir));
  } else {
    for (StoredMesh& stored : store->LoadAll()) {
      const auto start = std::chrono::steady_clock::now();
      const StatusOr<std::shared_ptr<const MeshEntry>> entry =
          RestoreStoredMesh(&context, &stored, start);
      if (!entry.ok()) {
        spdlog::error("store: mesh={} tenant={} not restored: {}", stored.id,
                      EscapeForLog(stored.tenant), entry.status().ToString());
        continue;
      }
      ++count;
      spdlog::info(
          "store: mesh={} tenant={} restored in {:.0f} ms", stored.id, EscapeForLog(stored.tenant),
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count());
    }
    spdlog::info("store: {} meshes restored from '{}'", count, EscapeForLog(dir));
  }
  context.set_store(std::move(store));
  if (shared) context.set_restorer(std::make_unique<StoreRestorer>(&context));
  if (restored != nullptr) *restored = count;
  return Status::Ok();
}

Status DeformServer::UseTokenFile(const std::string& path) {
  return impl_->context.auth().LoadTokenFile(path);
}

Status DeformServer::ReloadTokens() {
  const Status reloaded = impl_->context.auth().Reload();
  if (reloaded.ok()) {
    // Streams opened with a token that is gone or now names another tenant or role end now.
    const int revoked = impl_->context.streams().RevokeInvalid(impl_->context.auth());
    spdlog::info("token file reloaded; {} open streams ended (their token was revoked or changed)",
                 revoked);
  } else {
    spdlog::error("token file reload failed, the previous tokens stay in force: {}",
                  reloaded.ToString());
  }
  return reloaded;
}

int DeformServer::port() const { return impl_->port; }

int DeformServer::metrics_port() const {
  return impl_->metrics != nullptr ? impl_->metrics->port() : 0;
}

int DeformServer::open_connections() const {
  return impl_->acceptor != nullptr ? impl_->acceptor->open_connections() : 0;
}

std::string DeformServer::listening_address() const {
  return std::string(SplitListenAddress(impl_->options.listen_address).host) + ":" +
         std::to_string(impl_->port);
}

StatusOr<std::shared_ptr<const MeshEntry>> DeformServer::Preload(ModelInput input,
                                                                 const std::string& name,
                                                                 const std::string& tenant) {
  DEFORM_ASSIGN_OR_RETURN(Admission::MeshSlot reservation,
                          impl_->context.admission().ReserveMesh(tenant));
  LoadJob job;
  job.name = name.empty() ? input.description : name;
  job.mesh = std::move(input.mesh);
  job.skeleton = std::move(input.skeleton);
  job.options = ModelOptions::Paper();
  job.metrics = &impl_->context.metrics();
  return BuildAndRegister(&impl_->context, std::move(reservation), std::move(job));
}

void DeformServer::Shutdown(std::chrono::milliseconds grace) {
  MutexLock lock(&impl_->shutdown_mutex);
  if (impl_->shut_down) return;
  impl_->shut_down = true;
  if (impl_->server != nullptr) {
    spdlog::info("draining: {} open streams", impl_->context.streams().count());
    if (grpc::HealthCheckServiceInterface* health = impl_->server->GetHealthCheckService()) {
      health->SetServingStatus(false);
    }
    if (impl_->options.drain_delay_ms > 0) {
      spdlog::info("draining: NOT_SERVING for {} ms before the streams end (--drain-delay-ms)",
                   impl_->options.drain_delay_ms);
      std::this_thread::sleep_for(std::chrono::milliseconds(impl_->options.drain_delay_ms));
    }
    impl_->acceptor->Stop();  // no new connections
    impl_->context.streams().DrainAll();
    impl_->context.shutting_down().Cancel();  // builds in progress stop at the end of their phase
    impl_->server->Shutdown(std::chrono::system_clock::now() + grace);
    impl_->server->Wait();
  }
  for (const auto& stop : impl_->transport_stops) stop(grace / 10);
  impl_->context.pool().Shutdown();
  impl_->metrics.reset();
  spdlog::info("stopped");
}

void DeformServer::AddTransportStop(std::function<void(std::chrono::milliseconds)> stop) {
  impl_->transport_stops.push_back(std::move(stop));
}

ServiceContext& DeformServer::context() { return impl_->context; }

}  // namespace deform::service
