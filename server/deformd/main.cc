// deformd: the real-time deformation server.
//
//   deformd [--listen ADDR] [--workers N] [--batch-frames N] [--parallel-solve-min-mb N]
//           [--max-vertices N] [--max-meshes N] [--max-memory-mb N] [--max-message-mb N]
//           [--max-upload-mb N] [--max-bone-surface-mb N] [--log-level LEVEL]
//           [--preload MESH:SKELETON]... [--preload-phantom N]... [--shutdown-grace-s S]
//           [--keepalive-s S] [--keepalive-timeout-s S] [--idle-timeout-s S]
//           [--max-connections N] [--max-connections-per-address N]
//           [--tls-cert PEM --tls-key PEM [--tls-client-ca PEM]] [--plaintext]
//           [--token-file FILE] [--tenant-max-meshes N] [--tenant-max-streams N]
//           [--tenant-max-memory-mb N] [--preload-tenant NAME]
//           [--store DIR [--store-key FILE] [--store-shared]] [--drain-delay-ms N]
//           [--metrics ADDR]
//           [--http ADDR [--http-root DIR] [--http-max-connections N]
//            [--http-max-connections-per-address N]
//            [--http-allowed-host NAME]...]
//   deformd --version   prints "deformd VERSION (commit COMMIT)" (core/base/build_info.h)
//
// --metrics ADDR serves GET /metrics in Prometheus' format on its own port: plain HTTP, on a
// loopback address unless --plaintext, and with a token file for operators' tokens only
// (service/metrics_endpoint.h).
//
// --http ADDR also serves the browser viewer and the API over HTTP and WebSockets
// (service/rpc/web_server.h) from the same service context; its files come from --http-root, by
// default the `web` directory beside the executable (the build copies client/web there), else
// ../share/deformd/web.
//
// --store DIR keeps loaded meshes on disk and builds them again, under their ids and owners, when
// the server starts (service/mesh_store.h); preloads are not kept (their flags bring them back).
// With --store-shared the directory is a cluster's, shared by its replicas, and meshes are built
// when a call first names them (docs/cluster.md).
//
// Transport: TLS with --tls-cert/--tls-key (mutual TLS with --tls-client-ca); without a
// certificate, plaintext on a loopback address only, unless --plaintext
// (service/transport_security.h). Each of these flags also reads an environment variable
// (DEFORMD_TLS_CERT, DEFORMD_TLS_KEY, DEFORMD_TLS_CLIENT_CA, DEFORMD_PLAINTEXT=1); a flag given on
// the command line wins.
//
// Preloaded meshes are built before the server listens. SIGTERM or SIGINT drains: open streams
// end with UNAVAILABLE, calls in progress get most of --shutdown-grace-s, and the process exits 0
// within the grace period whatever the clients do (ExitWithinGrace). SIGHUP reloads the token
// file (service/identity.h; a bad file keeps the old tokens, logged).
#include <pthread.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/base/build_info.h"
#include "core/io/model_input.h"
#include "service/access/identity.h"
#include "service/base/log_text.h"
#include "service/base/open_files_limit.h"
#include "service/base/service_options.h"
#include "service/rpc/deform_server.h"
#include "service/rpc/web_server.h"

namespace {

using deform::service::DeformServer;
using deform::service::ServerOptions;

struct Args {
  ServerOptions server;
  std::size_t max_memory_mb = 4096;
  double parallel_solve_min_mb = 8;
  double float32_factor_min_mb = 64;
  int max_message_mb = 64;
  std::size_t max_upload_mb = 256;
  std::size_t max_bone_surface_mb = 16;
  double upload_idle_timeout_s = 30;
  double upload_time_limit_s = 300;
  std::string log_level = "info";
  std::vector<std::string> preload;
  std::vector<int> preload_phantom;
  double shutdown_grace_s = 5;
  std::string token_file;
  std::string store_dir;
  std::size_t tenant_max_memory_mb = 0;
  std::string preload_tenant = deform::service::Identity::Implicit().tenant;
  double keepalive_s = 30;
  double keepalive_timeout_s = 10;
  double idle_timeout_s = 300;
  std::string store_key;
  bool store_shared = false;
  std::string http_address;
  std::string http_root;
  int http_max_connections = 64;
  int http_max_connections_per_address = 32;
  std::vector<std::string> http_allowed_hosts;
};

// The viewer's files when --http-root is not given: `web` beside the executable, else
// ../share/deformd/web (an installed layout); empty when neither exists.
std::string DefaultHttpRoot() {
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return {};
  for (const auto& candidate :
       {exe.parent_path() / "web", exe.parent_path().parent_path() / "share/deformd/web"}) {
    if (std::filesystem::is_directory(candidate, error)) return candidate.string();
  }
  return {};
}

// One mesh to load before serving: files (--preload MESH:SKELETON) or the phantom
// (--preload-phantom N). `flag` is the flag as given, for error messages.
struct PreloadRequest {
  std::string flag;
  std::string mesh_path;
  std::string skeleton_path;
  int phantom_vertices = 0;
};

// Every --preload and --preload-phantom, in that order; false (logged) for a malformed spec.
bool CollectPreloads(const Args& args, std::vector<PreloadRequest>* requests) {
  for (const std::string& spec : args.preload) {
    const std::size_t colon = spec.rfind(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == spec.size()) {
      spdlog::error("--preload '{}' is not MESH:SKELETON", spec);
      return false;
    }
    requests->push_back(
        {"--preload '" + spec + "'", spec.substr(0, colon), spec.substr(colon + 1), 0});
  }
  for (const int vertices : args.preload_phantom) {
    requests->push_back({"--preload-phantom " + std::to_string(vertices), "", "", vertices});
  }
  return true;
}

bool PreloadAll(const Args& args, DeformServer* server) {
  std::vector<PreloadRequest> requests;
  if (!CollectPreloads(args, &requests)) return false;
  const deform::MeshLimits limits{args.server.limits.max_vertices,
                                  deform::MeshLimits{}.max_triangles};
  for (const PreloadRequest& request : requests) {
    auto input = deform::LoadModelInput(request.mesh_path, request.skeleton_path,
                                        request.phantom_vertices, limits);
    if (!input.ok()) {
      spdlog::error("{}: {}", request.flag, input.status().ToString());
      return false;
    }
    const std::string name = input->description;
    auto entry = server->Preload(std::move(*input), name, args.preload_tenant);
    if (!entry.ok()) {
      spdlog::error("{}: {}", request.flag, entry.status().ToString());
      return false;
    }
  }
  return true;
}

// Drains `server` and ends the process with exit code 0 within `grace_s` seconds of being called,
// whatever the clients do: calls in progress get 70% of the grace period, then gRPC cancels them
// (an idle client connection makes gRPC wait that long too); should the drain still not be done
// at 95% of the period (a frozen stream's write that never completes), the process exits without
// it. Destructors are skipped either way: gRPC's library teardown can wait on idle connections.
[[noreturn]] void ExitWithinGrace(DeformServer* server, double grace_s) {
  const auto grace = std::chrono::milliseconds(static_cast<long>(grace_s * 1000));
  std::promise<void> drained;
  std::future<void> done = drained.get_future();
  std::thread drainer([server, grace, &drained] {
    server->Shutdown(grace * 7 / 10);
    drained.set_value();
  });
  if (done.wait_for(grace * 19 / 20) == std::future_status::ready) {
    drainer.join();
  } else {
    spdlog::warn("the drain did not finish within the {} s grace period; exiting without it",
                 grace_s);
    drainer.detach();
  }
  spdlog::default_logger()->flush();
  std::fflush(nullptr);
  std::_Exit(0);
}

}  // namespace

int main(int argc, char** argv) {
  // Every thread inherits this mask; the main thread alone takes the signals, with sigwait().
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  Args args;
  CLI::App app{"deformd: real-time skeleton-driven deformation server (gRPC deform.v1)"};
  app.add_option("--listen", args.server.listen_address, "Address to listen on, host:port")
      ->capture_default_str();
  app.add_option(
         "--workers", args.server.workers,
         "Worker threads for solves and precomputation; 0 = one per CPU this process may use "
         "(its affinity and cgroup CPU quota)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
  app.add_option("--batch-frames", args.server.batch_frames,
                 "Frames of streams on one mesh solved in one pass over its factor, at most; 1 = "
                 "each alone")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
  app.add_option("--parallel-solve-min-mb", args.parallel_solve_min_mb,
                 "A lone stream's frames of a mesh whose factor holds this many MiB or more are "
                 "split over the idle workers while fewer streams than workers are open")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e9));
  app.add_option("--float32-factor-min-mb", args.float32_factor_min_mb,
                 "A mesh whose factor holds this many MiB or more (in double) stores it in "
                 "float32, where a probe solve shows its frames within 2.5e-7 of the diagonal; "
                 "-1 = never")
      ->capture_default_str()
      ->check(CLI::Range(-1.0, 1e9));
  app.add_option("--max-vertices", args.server.limits.max_vertices, "Largest mesh, in vertices")
      ->capture_default_str();
  app.add_option("--max-meshes", args.server.limits.max_meshes, "Meshes loaded at once")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 20));
  app.add_option("--max-memory-mb", args.max_memory_mb,
                 "Memory budget for loaded meshes (factor + geometry estimate), MiB")
      ->capture_default_str();
  app.add_option("--max-message-mb", args.max_message_mb, "Largest gRPC message, MiB")
      ->capture_default_str()
      ->check(CLI::Range(1, 2047));
  app.add_option("--max-upload-mb", args.max_upload_mb, "Largest LoadMesh upload, MiB")
      ->capture_default_str();
  app.add_option("--max-bone-surface-mb", args.max_bone_surface_mb,
                 "Largest total of an upload's bone surface files (sent in its header), MiB")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{0}, std::size_t{1} << 20));
  app.add_option("--max-streams", args.server.limits.max_streams,
                 "Open Deform streams on the server, all tenants; 0 = no limit")
      ->capture_default_str()
      ->check(CLI::Range(0, 1 << 20));
  app.add_option("--upload-idle-timeout-s", args.upload_idle_timeout_s,
                 "End an upload that sends no data for this long (DEADLINE_EXCEEDED); 0 = never")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  app.add_option("--upload-time-limit-s", args.upload_time_limit_s,
                 "End an upload not complete after this long (DEADLINE_EXCEEDED); 0 = never")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  app.add_option("--log-level", args.log_level, "trace, debug, info, warn, error or off")
      ->capture_default_str()
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.add_option("--preload", args.preload,
                 "Load MESH:SKELETON (files) before serving; repeatable");
  app.add_option("--preload-phantom", args.preload_phantom,
                 "Load the knee phantom with about N vertices before serving; repeatable");
  app.add_option("--shutdown-grace-s", args.shutdown_grace_s,
                 "On SIGTERM/SIGINT, seconds given to calls in progress")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 600.0));
  app.add_option("--tls-cert", args.server.security.cert_file,
                 "PEM certificate chain: serve TLS (with --tls-key)")
      ->envname("DEFORMD_TLS_CERT");
  app.add_option("--tls-key", args.server.security.key_file, "PEM private key of --tls-cert")
      ->envname("DEFORMD_TLS_KEY");
  app.add_option("--tls-client-ca", args.server.security.client_ca_file,
                 "PEM CA of client certificates: mutual TLS, clients without one are refused")
      ->envname("DEFORMD_TLS_CLIENT_CA");
  app.add_flag("--tls-allow-expired", args.server.security.allow_expired_certificate,
               "Serve a certificate that has expired or is not yet valid instead of refusing "
               "to start")
      ->envname("DEFORMD_TLS_ALLOW_EXPIRED");
  app.add_flag("--plaintext", args.server.security.allow_plaintext,
               "Without a certificate, serve plaintext on a non-loopback address too")
      ->envname("DEFORMD_PLAINTEXT");
  app.add_option("--token-file", args.token_file,
                 "Bearer tokens: lines 'SHA256-HEX TENANT tenant|operator'; reloaded on SIGHUP. "
                 "Without it every caller is one implicit tenant")
      ->envname("DEFORMD_TOKEN_FILE");
  app.add_option("--tenant-max-meshes", args.server.limits.tenant_max_meshes,
                 "Meshes loaded at once per tenant; 0 = no per-tenant limit")
      ->capture_default_str()
      ->check(CLI::Range(0, 1 << 20));
  app.add_option("--tenant-max-streams", args.server.limits.tenant_max_streams,
                 "Open Deform streams per tenant; 0 = no per-tenant limit")
      ->capture_default_str()
      ->check(CLI::Range(0, 1 << 20));
  app.add_option("--tenant-max-memory-mb", args.tenant_max_memory_mb,
                 "Memory budget per tenant (same estimate as --max-memory-mb), MiB; 0 = none")
      ->capture_default_str();
  app.add_option("--metrics", args.server.metrics_address,
                 "Serve Prometheus metrics at http://ADDR/metrics (host:port; port 0 picks one; a "
                 "non-loopback address needs --plaintext)")
      ->envname("DEFORMD_METRICS");
  app.add_option("--store", args.store_dir,
                 "Keep loaded meshes in DIR (0700) and restore them at start-up")
      ->envname("DEFORMD_STORE");
  app.add_option("--store-key", args.store_key,
                 "The --store entries' HMAC key (32 bytes, created 0600 if missing; outside the "
                 "store): an entry whose owner was edited is refused at restore")
      ->envname("DEFORMD_STORE_KEY");
  app.add_flag("--store-shared", args.store_shared,
               "The --store directory is shared by the replicas of a cluster (needs --store-key, "
               "the same on every replica): meshes are built on demand, not restored at start")
      ->envname("DEFORMD_STORE_SHARED");
  app.add_option("--drain-delay-ms", args.server.drain_delay_ms,
                 "On SIGTERM, milliseconds of NOT_SERVING health before the streams end (for a "
                 "balancer to stop routing here; within --shutdown-grace-s)")
      ->check(CLI::Range(0, 600'000))
      ->capture_default_str()
      ->envname("DEFORMD_DRAIN_DELAY_MS");
  app.add_option("--preload-tenant", args.preload_tenant,
                 "Tenant that owns the --preload and --preload-phantom meshes")
      ->capture_default_str()
      ->check([](const std::string& name) {
        return deform::service::IsValidTenantName(name)
                   ? std::string()
                   : std::string("a tenant is 1 to 64 characters of A-Z a-z 0-9 . _ -");
      });
  app.add_option("--keepalive-s", args.keepalive_s,
                 "Ping a connection after this many seconds without activity")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 86400.0));
  app.add_option("--keepalive-timeout-s", args.keepalive_timeout_s,
                 "Close a connection whose ping is unanswered for this many seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 3600.0));
  app.add_option("--idle-timeout-s", args.idle_timeout_s,
                 "Close a connection without any call for this many seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 86400.0));
  app.add_option("--max-connections", args.server.connections.max_connections,
                 "Open gRPC connections at once; more are closed at their accept (0: from the "
                 "open-files limit, two descriptors each and 256 kept for the rest)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1 << 20));
  app.add_option("--max-connections-per-address",
                 args.server.connections.max_connections_per_address,
                 "Of them, at most this many from one peer address (so one peer cannot take them "
                 "all; a balancer in front is one address)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 20));
  app.add_option("--http", args.http_address,
                 "Also serve the browser viewer, the API over HTTP and its streams over "
                 "WebSockets on ADDR (host:port; port 0 = any); plaintext: loopback only unless "
                 "--plaintext");
  app.add_option("--http-root", args.http_root,
                 "The viewer's files (default: 'web' beside the executable)");
  app.add_option("--http-max-connections", args.http_max_connections,
                 "Open HTTP and WebSocket connections at once")
      ->capture_default_str()
      ->check(CLI::Range(1, 65536));
  app.add_option("--http-max-connections-per-address", args.http_max_connections_per_address,
                 "Of them, at most this many from one peer address (so one peer cannot take them "
                 "all)")
      ->capture_default_str()
      ->check(CLI::Range(1, 65536));
  app.add_option("--http-allowed-host", args.http_allowed_hosts,
                 "A Host name the HTTP port answers beside localhost, 127.0.0.1, [::1] and the "
                 "--http host (repeatable; any other Host is refused 403: DNS rebinding)")
      ->allow_extra_args(false);
  app.set_version_flag("--version", deform::VersionLine("deformd"));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  deform::service::InstallEscapingDefaultLogger();  // no control byte reaches the log
  spdlog::set_level(spdlog::level::from_str(args.log_level));
  spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%^%l%$] %v");
  // Each connection takes a descriptor at its accept: the soft limit up to the hard one.
  const deform::service::OpenFilesLimit files = deform::service::RaiseOpenFilesLimit();
  if (!files.error.empty()) {
    spdlog::warn("open files: {} (soft limit {}, hard {}); connections beyond it are refused",
                 files.error, files.soft, files.hard);
  } else if (files.soft != files.soft_before) {
    spdlog::info("open files: soft limit raised from {} to {} (the hard limit {})",
                 files.soft_before, files.soft, files.hard);
  }
  args.server.limits.max_memory_bytes = args.max_memory_mb << 20;
  args.server.parallel_solve_min_factor_bytes =
      static_cast<std::size_t>(args.parallel_solve_min_mb * 1024 * 1024);
  args.server.float32_factor_min_bytes =
      args.float32_factor_min_mb < 0
          ? -1
          : static_cast<std::int64_t>(args.float32_factor_min_mb * 1024 * 1024);
  args.server.limits.max_upload_bytes = args.max_upload_mb << 20;
  args.server.limits.max_bone_surface_bytes = args.max_bone_surface_mb << 20;
  args.server.limits.upload_idle_timeout_ms =
      static_cast<long long>(args.upload_idle_timeout_s * 1000);
  args.server.limits.upload_time_limit_ms = static_cast<long long>(args.upload_time_limit_s * 1000);
  args.server.max_message_bytes = args.max_message_mb << 20;
  args.server.limits.tenant_max_memory_bytes = args.tenant_max_memory_mb << 20;
  args.server.connections.keepalive_time_ms = static_cast<int>(args.keepalive_s * 1000);
  args.server.connections.keepalive_timeout_ms = static_cast<int>(args.keepalive_timeout_s * 1000);
  args.server.connections.max_connection_idle_ms = static_cast<int>(args.idle_timeout_s * 1000);

  std::unique_ptr<deform::web::WebServer> web;  // declared first: outlives the server's Shutdown
  DeformServer server(args.server);
  if (!args.token_file.empty()) {
    const deform::Status tokens = server.UseTokenFile(args.token_file);
    if (!tokens.ok()) {
      spdlog::error("--token-file: {}", tokens.ToString());
      return 1;
    }
  }
  if (!args.store_dir.empty()) {
    const deform::Status store =
        server.UseStore(args.store_dir, nullptr, args.store_key, args.store_shared);
    if (!store.ok()) {
      spdlog::error("--store: {}", store.ToString());
      return 1;
    }
  }
  if (!PreloadAll(args, &server)) return 1;
  if (!args.http_address.empty()) {
    deform::web::WebOptions web_options;
    web_options.address = args.http_address;
    web_options.static_root = args.http_root.empty() ? DefaultHttpRoot() : args.http_root;
    web_options.max_connections = args.http_max_connections;
    web_options.max_connections_per_address = args.http_max_connections_per_address;
    web_options.allowed_hosts = args.http_allowed_hosts;
    web_options.allow_plaintext = args.server.security.allow_plaintext;
    if (web_options.static_root.empty()) {
      spdlog::error("--http: no viewer files beside the executable; give --http-root DIR");
      return 1;
    }
    web = std::make_unique<deform::web::WebServer>(&server.context(), web_options);
    server.AddTransportStop([&web](std::chrono::milliseconds grace) { web->Stop(grace); });
  }
  const deform::Status started = server.Start();
  if (!started.ok()) {
    spdlog::error("{}", started.ToString());
    return 1;
  }
  if (web != nullptr) {
    const deform::Status web_started = web->Start();
    if (!web_started.ok()) {
      spdlog::error("{}", web_started.ToString());
      return 1;
    }
  }

  int signal_number = 0;
  for (;;) {
    sigwait(&stop_signals, &signal_number);
    if (signal_number != SIGHUP) break;
    if (args.token_file.empty()) {
      spdlog::info("received SIGHUP: no token file to reload");
    } else {
      spdlog::info("received SIGHUP: reloading the token file");
      (void)server.ReloadTokens();  // logs the outcome; a bad file keeps the old tokens
    }
  }
  spdlog::info("received {}, shutting down", signal_number == SIGTERM ? "SIGTERM" : "SIGINT");
  ExitWithinGrace(&server, args.shutdown_grace_s);
}
