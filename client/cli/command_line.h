// What deform-vr and deform-loadtest share on the command line: the server address and connection
// timeout, where the mesh comes from, parsing with the project's exit codes (0 for --help, 2 for a
// usage error with one line on stderr), and one-line failure reports (exit code 1).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <string>

#include "cli/mesh_source.h"
#include "lib/deform_client.h"

namespace deform::cli {

// How to talk to a secured server: TLS files and the bearer token.
struct SecurityArgs {
  bool tls = false;       // --tls: TLS with the system's trusted roots
  std::string ca_file;    // --tls-ca: the server's CA (implies TLS)
  std::string cert_file;  // --tls-cert / --tls-key: client certificate for mutual TLS
  std::string key_file;
  std::string server_name;  // --tls-server-name: the name the server's certificate carries
  std::string token;        // --token: bearer token
};

// --tls, --tls-ca, --tls-cert, --tls-key, --tls-server-name, --token; each also read from the
// environment (DEFORM_TLS=1, DEFORM_TLS_CA, DEFORM_TLS_CERT, DEFORM_TLS_KEY,
// DEFORM_TLS_SERVER_NAME, DEFORM_TOKEN), the command line winning.
void AddSecurityFlags(CLI::App& app, SecurityArgs* args);

// Client options from the security flags (TLS when any TLS flag is given, reading the files):
// NOT_FOUND naming an unreadable file, INVALID_ARGUMENT for a certificate without its key.
grpc::Status MakeClientOptions(const SecurityArgs& args, client::ClientOptions* options);

struct ConnectionArgs {
  std::string target = "127.0.0.1:50051";  // host:port
  int connect_timeout_ms = 5000;           // how long to wait for the server to be reachable
  SecurityArgs security;
};

// --target, --connect-timeout-ms and the security flags (AddSecurityFlags).
void AddConnectionFlags(CLI::App& app, ConnectionArgs* args);

// The options AddMeshSourceFlags adds, for further constraints (e.g. excludes).
struct MeshSourceOptions {
  CLI::Option* mesh = nullptr;
  CLI::Option* skeleton = nullptr;
  CLI::Option* weights = nullptr;
  CLI::Option* phantom_vertices = nullptr;
  CLI::Option* rotation_blend = nullptr;
  CLI::Option* bone_surfaces = nullptr;
};

// --mesh and --skeleton (each needs the other, except that a .gltf/.glb rig takes no skeleton),
// --weights (needs --mesh), --phantom-vertices (excludes --mesh), --rotation-blend,
// --bone-surface FILE:BONE (repeatable, needs --mesh), --phantom-without-bones (excludes --mesh),
// --contacts on|off and --keep-volume on|off (MethodOptions.constraints), filling
// `source` (which must outlive the parse). The skeleton rule is checked once parsing completes
// (app's parse_complete_callback: a usage error).
MeshSourceOptions AddMeshSourceFlags(CLI::App& app, MeshSource* source);

// Adds --version (VersionLine(program), core/base/build_info.h) and parses the command line.
// Returns the exit code the program should end with (0 after --help or --version, 2 after a usage
// error, reported on stderr as "program: message"), or nullopt to go on.
std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv, const char* program);

// Writes "program: STATUS_NAME: message" to stderr and returns 1 (the runtime-error exit code).
int ReportFailure(const char* program, const grpc::Status& status);

// Waits up to args.connect_timeout_ms for the server; UNAVAILABLE naming the target otherwise.
grpc::Status WaitForServer(client::DeformClient& client, const ConnectionArgs& args);

// A command-line client's run: connects (WaitForServer), acquires the mesh (AcquireMesh), calls
// `run_on_mesh`, then unloads the mesh when `unload(loaded)` says so (`loaded`: this run loaded
// it). Failures are reported as "program: ..." lines. Returns run_on_mesh's exit code, or 1 when
// connecting, acquiring or (after a successful run) unloading failed.
int RunOnAcquiredMesh(
    const char* program, const ConnectionArgs& connection, const MeshSource& source,
    const std::function<int(client::DeformClient&, const deform::v1::MeshSummary&)>& run_on_mesh,
    const std::function<bool(bool loaded)>& unload);

}  // namespace deform::cli
