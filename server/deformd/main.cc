// deformd: the real-time deformation server.
//
//   deformd [--listen ADDR] [--workers N] [--max-vertices N] [--max-meshes N] [--max-memory-mb N]
//           [--max-message-mb N] [--max-upload-mb N] [--log-level LEVEL]
//           [--preload MESH:SKELETON]... [--preload-phantom N]... [--shutdown-grace-s S]
//           [--keepalive-s S] [--keepalive-timeout-s S] [--idle-timeout-s S]
//
// Preloaded meshes are built before the server listens. SIGTERM or SIGINT drains: open streams
// end with UNAVAILABLE, calls in progress get most of --shutdown-grace-s, and the process exits 0
// within the grace period whatever the clients do (ExitWithinGrace).
#include <pthread.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <thread>
#include <string>
#include <vector>

#include "core/io/model_input.h"
#include "service/deform_server.h"
#include "service/service_options.h"

namespace {

using deform::service::DeformServer;
using deform::service::ServerOptions;

struct Args {
  ServerOptions server;
  std::size_t max_memory_mb = 4096;
  int max_message_mb = 64;
  std::size_t max_upload_mb = 256;
  std::string log_level = "info";
  std::vector<std::string> preload;
  std::vector<int> preload_phantom;
  double shutdown_grace_s = 5;
  double keepalive_s = 30;
  double keepalive_timeout_s = 10;
  double idle_timeout_s = 300;
};

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
    auto entry = server->Preload(std::move(*input), name);
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
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  Args args;
  CLI::App app{"deformd: real-time skeleton-driven deformation server (gRPC deform.v1)"};
  app.add_option("--listen", args.server.listen_address, "Address to listen on, host:port")
      ->capture_default_str();
  app.add_option("--workers", args.server.workers,
                 "Worker threads for solves and precomputation; 0 = one per core")
      ->capture_default_str()
      ->check(CLI::Range(0, 1024));
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  spdlog::set_level(spdlog::level::from_str(args.log_level));
  spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%^%l%$] %v");
  args.server.limits.max_memory_bytes = args.max_memory_mb << 20;
  args.server.limits.max_upload_bytes = args.max_upload_mb << 20;
  args.server.max_message_bytes = args.max_message_mb << 20;
  args.server.connections.keepalive_time_ms = static_cast<int>(args.keepalive_s * 1000);
  args.server.connections.keepalive_timeout_ms = static_cast<int>(args.keepalive_timeout_s * 1000);
  args.server.connections.max_connection_idle_ms = static_cast<int>(args.idle_timeout_s * 1000);

  DeformServer server(args.server);
  if (!PreloadAll(args, &server)) return 1;
  const deform::Status started = server.Start();
  if (!started.ok()) {
    spdlog::error("{}", started.ToString());
    return 1;
  }

  int signal_number = 0;
  sigwait(&stop_signals, &signal_number);
  spdlog::info("received {}, shutting down", signal_number == SIGTERM ? "SIGTERM" : "SIGINT");
  ExitWithinGrace(&server, args.shutdown_grace_s);
}
