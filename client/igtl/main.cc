// deform-igtl-bridge: deformd to OpenIGTLink (3D Slicer, operating-room software). Loads a mesh
// or uses a loaded one, opens one deform stream and serves OpenIGTLink receivers: the skin's
// topology once, then every frame's points and bone transforms; joint angles come back as STRING
// messages. The messages, device names and conventions: docs/clients/openigtlink.md.
//
//   deform-igtl-bridge [--target ADDR] [--mesh FILE --skeleton FILE | --mesh-id ID]
//                      [--igtl-listen HOST:PORT] [--igtl-allow-remote] [--rate HZ]
//                      [--ras-axes AXES] [--mm-per-unit S]
//
// Runs until SIGINT or SIGTERM. Exit codes: 0 after a signal, 1 runtime or server error (one line
// on stderr naming the gRPC status code), 2 usage error.
#include <pthread.h>
#include <signal.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <iostream>
#include <string>
#include <thread>

#include "cli/command_line.h"
#include "cli/mesh_source.h"
#include "igtl/bridge.h"
#include "igtl/ras_frame.h"
#include "igtl/receiver_hub.h"
#include "service/base/listen_address.h"
#include "service/base/log_text.h"

namespace {

constexpr char kProgram[] = "deform-igtl-bridge";

struct BridgeArgs {
  deform::cli::ConnectionArgs connection;
  deform::cli::MeshSource source;
  std::string igtl_listen = "127.0.0.1:18944";
  bool allow_remote = false;
  std::string ras_axes = "x,y,z";
  double mm_per_unit = 1.0;
  bool keep_mesh = false;
  deform::igtl_bridge::BridgeSettings settings;
};

void AddFlags(CLI::App& app, BridgeArgs& args) {
  deform::cli::AddConnectionFlags(app, &args.connection);
  const deform::cli::MeshSourceOptions source = deform::cli::AddMeshSourceFlags(app, &args.source);
  CLI::Option* mesh_id = app.add_option("--mesh-id", args.source.mesh_id,
                                        "Use a mesh the server already holds (never unloaded)");
  mesh_id->excludes(source.mesh)->excludes(source.skeleton)->excludes(source.phantom_vertices);
  source.rotation_blend->excludes(mesh_id);
  app.add_option("--igtl-listen", args.igtl_listen,
                 "OpenIGTLink address HOST:PORT, numeric IPv4 (port 0: one the kernel picks)")
      ->capture_default_str();
  app.add_flag("--igtl-allow-remote", args.allow_remote,
               "Allow a non-loopback --igtl-listen: OpenIGTLink has no authentication and no "
               "encryption, so anyone who reaches the port sees the mesh and poses it");
  app.add_option("--rate", args.settings.rate_hz,
                 "Poses (so frames) a second; 0: only when a receiver changes an angle")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--max-receivers", args.settings.max_receivers,
                 "OpenIGTLink connections served at once")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  app.add_flag("--full-frames", args.settings.full_frames,
               "Send every frame as the full POLYDATA 'Skin' (points and triangles) instead of "
               "the points-only 'SkinPoints'");
  app.add_option("--ras-axes", args.ras_axes,
                 "Model axes that become R,A,S, signed (e.g. -x,z,y for a Y-up model facing +Z)")
      ->capture_default_str();
  app.add_option("--mm-per-unit", args.mm_per_unit,
                 "Millimetres per model unit (100 for a mesh in decimetres)")
      ->capture_default_str();
  app.add_flag("--keep-mesh", args.keep_mesh, "Leave a mesh this run loaded on the server");
}

// Checks --igtl-listen, --ras-axes and --mm-per-unit into `args.settings`; false with `error`.
bool Resolve(BridgeArgs& args, std::string* error) {
  const deform::service::ListenHostAndPort split =
      deform::service::SplitListenAddress(args.igtl_listen);
  const int port = deform::service::ListenPort(split);
  if (port < 0) {
    *error = "--igtl-listen: not HOST:PORT with a port 0-65535: " + args.igtl_listen;
    return false;
  }
  args.settings.listen_host = std::string(split.host);
  args.settings.listen_port = port;
  if (!args.allow_remote && !deform::igtl_bridge::IsLoopbackAddress(args.settings.listen_host)) {
    *error = "--igtl-listen " + args.igtl_listen +
             " is not a loopback address: OpenIGTLink has no authentication or encryption; "
             "add --igtl-allow-remote to serve it anyway";
    return false;
  }
  if (!deform::igtl_bridge::RasFrame::Parse(args.ras_axes, args.mm_per_unit, &args.settings.frame,
                                            error)) {
    *error = "--ras-axes/--mm-per-unit: " + *error;
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "deform-igtl-bridge: serves a deformd mesh's deform stream to OpenIGTLink receivers (3D "
      "Slicer). Each receiver gets the skin as POLYDATA 'Skin' (points and triangles) once, then "
      "per frame POLYDATA 'SkinPoints' (points only) and a TRANSFORM per bone; STRING messages "
      "'JOINT:AXIS:DEGREES[,...]' or 'rest' set joint angles. Loads the mesh given (default: the "
      "built-in knee phantom) and unloads it at the end; runs until SIGINT or SIGTERM."};
  app.get_formatter()->column_width(34);
  BridgeArgs args;
  AddFlags(app, args);
  if (const auto exit_code = deform::cli::ParseCommandLine(app, argc, argv, kProgram)) {
    return *exit_code;
  }
  std::string error;
  if (!Resolve(args, &error)) {
    std::cerr << kProgram << ": " << error << "\n";
    return 2;
  }
  deform::service::InstallEscapingDefaultLogger();

  // SIGINT and SIGTERM are taken by one thread (blocked in every other, which inherit the mask).
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::atomic<bool> stop{false};
  std::thread signal_thread([&] {
    int received = 0;
    sigwait(&signals, &received);
    stop = true;
  });
  signal_thread.detach();

  return deform::cli::RunOnAcquiredMesh(
      kProgram, args.connection, args.source,
      [&](deform::client::DeformClient& client, const deform::v1::MeshSummary& summary) {
        return deform::igtl_bridge::RunBridge(client, summary, args.settings, stop);
      },
      [&](bool loaded) { return loaded && !args.keep_mesh; });
}
