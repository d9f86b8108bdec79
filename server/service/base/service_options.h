// Limits and settings of the deformation service. Plain values, no behaviour.
#pragma once

#include <cstddef>
#include <string>

namespace deform::service {

struct ServiceLimits {
  // Meshes with more vertices are refused with RESOURCE_EXHAUSTED. Default: 2,000,000.
  std::size_t max_vertices = 2'000'000;
  // Meshes loaded (or being loaded) at once. Default: 64.
  int max_meshes = 64;
  // Budget for loaded meshes, estimated by DeformationModel::EstimatedBytes (factor and geometry).
  // Default: 4 GiB.
  std::size_t max_memory_bytes = std::size_t{4} << 30;
  // Largest upload (mesh file plus skeleton file) accepted by LoadMesh. Default: 256 MiB.
  std::size_t max_upload_bytes = std::size_t{256} << 20;
  // Largest total of an upload's bone surface files (UploadSource.bone_surfaces, sent in the
  // header, so within the gRPC message limit too). Default: 16 MiB.
  std::size_t max_bone_surface_bytes = std::size_t{16} << 20;
  // Open Deform streams on the server, all tenants together (each holds a scratch and frame slots
  // of its mesh's size); 0 means no limit. Default: 256.
  int max_streams = 256;
  // An upload ends with DEADLINE_EXCEEDED (its slot and bytes released) when no data has arrived
  // for upload_idle_timeout_ms, or when it has lasted upload_time_limit_ms from its header to its
  // last byte (upload_watchdog.h); 0 disables either. Defaults: 30 s and 300 s.
  long long upload_idle_timeout_ms = 30'000;
  long long upload_time_limit_ms = 300'000;
  // Per tenant (identity.h), on top of the server-wide limits above; 0 means no per-tenant limit.
  // Meshes loaded or being loaded by one tenant. Default: 0.
  int tenant_max_meshes = 0;
  // Open Deform streams of one tenant. Default: 0.
  int tenant_max_streams = 0;
  // Memory budget of one tenant's loaded meshes (the same estimate as max_memory_bytes). Default:
  // 0.
  std::size_t tenant_max_memory_bytes = 0;
};

// How the gRPC port is secured (policy and credentials: transport_security.h).
struct TransportSecurity {
  // PEM files: the server's certificate chain and its private key. Both or neither.
  std::string cert_file;
  std::string key_file;
  // PEM file of the CA that signs client certificates. Given (with a certificate): mutual TLS,
  // a client without a certificate signed by it is refused during the handshake. Default: none.
  std::string client_ca_file;
  // Without a certificate, serve plaintext on a non-loopback address too. Default: false.
  bool allow_plaintext = false;
  // Serve a certificate outside its validity (expired, or not yet valid) instead of refusing to
  // start. Default: false.
  bool allow_expired_certificate = false;
};

// How the server treats connections (gRPC channel arguments; deformd's flags set them).
struct ConnectionOptions {
  // The server pings a connection after this long without activity, so a vanished or frozen peer
  // is found. Default: 30 s (GRPC_ARG_KEEPALIVE_TIME_MS).
  int keepalive_time_ms = 30'000;
  // A ping unanswered this long closes the connection and cancels its calls. Default: 10 s
  // (GRPC_ARG_KEEPALIVE_TIMEOUT_MS).
  int keepalive_timeout_ms = 10'000;
  // A connection without any call for this long is closed (the client reconnects on its next
  // call). Default: 5 min (GRPC_ARG_MAX_CONNECTION_IDLE_MS).
  int max_connection_idle_ms = 300'000;
  // Clients may ping at most this often (their keepalives); more often is answered with GOAWAY.
  // Default: 10 s (GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS).
  int min_client_ping_interval_ms = 10'000;
  // Open connections to the gRPC port in all; 0: from the open-files limit, two descriptors per
  // connection and 256 kept for the rest (connection_acceptor.h). More are closed at their accept.
  int max_connections = 0;
  // Open connections to the gRPC port from one peer address. Default: 256, the stream slots'.
  int max_connections_per_address = 256;
  // A connection that has not finished its TLS and HTTP/2 handshake this long after its accept
  // is closed (GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS). Default: 10 s.
  int handshake_timeout_ms = 10'000;
};

struct ServerOptions {
  // "host:port"; port 0 picks a free port (DeformServer::port() tells which). Default: loopback.
  std::string listen_address = "127.0.0.1:50051";
  // Worker threads for solves and precomputation; <= 0 means the number of cores. Default: 0.
  int workers = 0;
  // Frames of streams on the same mesh and stiffness solved in one pass over the factor at most
  // (the worker pool's batches, worker_pool.h); 1 solves every frame alone. Default: 8, where the
  // batched solve's time per frame levels off (docs/performance.md, "Batched solves").
  int batch_frames = 8;
  // A mesh whose factor holds at least this many bytes has its lone streams' frames split over
  // the idle workers (parallel_solve.h; with two or more workers). Default: 8 MiB, below which the
  // hand-over between threads costs more than it saves (docs/performance.md, "Parallel solve").
  std::size_t parallel_solve_min_factor_bytes = std::size_t{8} << 20;
  // A mesh whose factor holds at least this many bytes (in double) stores it in float32 where the
  // rounding keeps frames within a quarter of 1e-6 of the diagonal (ModelOptions::
  // float32_factor_min_bytes; the probe leaves the others in double); negative: never. Default:
  // 64 MiB, where the solve is bound by memory reads (a factor beyond the last-level cache);
  // factors the caches hold gain nothing (docs/performance.md, "Float32 factor").
  std::int64_t float32_factor_min_bytes = std::int64_t{64} << 20;
  // Largest gRPC message received or sent. Default: 64 MiB.
  int max_message_bytes = 64 << 20;
  // Where GET /metrics is served (metrics_endpoint.h), "host:port"; empty: not served. Default:
  // empty.
  std::string metrics_address;
  // On shutdown, how long the server reports NOT_SERVING through gRPC health while still serving
  // everything, before it stops accepting and ends the open streams (UNAVAILABLE): the time a
  // balancer's health check needs to send new streams elsewhere (docs/cluster.md). Counted in the
  // shutdown's grace period. Default: 0 (a single server has no balancer to wait for).
  int drain_delay_ms = 0;
  ConnectionOptions connections;
  ServiceLimits limits;
  TransportSecurity security;
};

}  // namespace deform::service
