#include "cli/command_line.h"

#include <iostream>

#include "cli/rotation_blend_flag.h"
#include "core/base/build_info.h"
#include "lib/status_names.h"

namespace deform::cli {

void AddSecurityFlags(CLI::App& app, SecurityArgs* args) {
  app.add_flag("--tls", args->tls, "Connect with TLS (the system's trusted roots unless --tls-ca)")
      ->envname("DEFORM_TLS");
  app.add_option("--tls-ca", args->ca_file, "PEM CA of the server's certificate (implies --tls)")
      ->envname("DEFORM_TLS_CA");
  app.add_option("--tls-cert", args->cert_file,
                 "PEM client certificate for mutual TLS (with --tls-key; implies --tls)")
      ->envname("DEFORM_TLS_CERT");
  app.add_option("--tls-key", args->key_file, "PEM private key of --tls-cert")
      ->envname("DEFORM_TLS_KEY");
  app.add_option(
         "--tls-server-name", args->server_name,
         "Name the server's certificate carries, when not the target's host (implies --tls)")
      ->envname("DEFORM_TLS_SERVER_NAME");
  app.add_option("--token", args->token,
                 "Bearer token sent with every call (deformd --token-file); prefer DEFORM_TOKEN, "
                 "which other users cannot read in the process list")
      ->envname("DEFORM_TOKEN");
}

grpc::Status MakeClientOptions(const SecurityArgs& args, client::ClientOptions* options) {
  options->token = args.token;
  const bool tls = args.tls || !args.ca_file.empty() || !args.cert_file.empty() ||
                   !args.key_file.empty() || !args.server_name.empty();
  if (!tls) return grpc::Status::OK;
  const grpc::Status loaded =
      client::LoadClientTlsFiles(args.ca_file, args.cert_file, args.key_file, &options->tls);
  options->tls.server_name = args.server_name;
  return loaded;
}

void AddConnectionFlags(CLI::App& app, ConnectionArgs* args) {
  AddSecurityFlags(app, &args->security);
  app.add_option("--target", args->target, "Server address host:port")->capture_default_str();
  app.add_option("--connect-timeout-ms", args->connect_timeout_ms,
                 "How long to wait for the server to be reachable")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
}

MeshSourceOptions AddMeshSourceFlags(CLI::App& app, MeshSource* source) {
  MeshSourceOptions options;
  options.mesh = app.add_option("--mesh", source->mesh_path,
                                "Mesh file to upload (.obj .ply .stl .off), or a skinned glTF rig "
                                "(.gltf .glb) that brings its skeleton and weights; default: the "
                                "built-in knee phantom");
  options.skeleton = app.add_option("--skeleton", source->skeleton_path,
                                    "Skeleton file (.tgf or JSON); required with --mesh, except a "
                                    "glTF rig");
  options.weights = app.add_option("--weights", source->weights_path,
                                   "The rig's skinning weights (.dmat or .csv: a row per vertex, "
                                   "a column per bone) to bind with; default: binding through "
                                   "the body");
  options.phantom_vertices = app.add_option("--phantom-vertices", source->phantom_vertices,
                                            "Phantom resolution (0 = the server's default)")
                                 ->capture_default_str()
                                 ->check(CLI::NonNegativeNumber);
  options.skeleton->needs(options.mesh);
  options.weights->needs(options.mesh);
  app.parse_complete_callback([source] {
    const bool rig = !source->mesh_path.empty() &&
                     client::MeshFormatFromPath(source->mesh_path) == deform::v1::MESH_FORMAT_GLTF;
    if (!source->mesh_path.empty() && source->skeleton_path.empty() && !rig) {
      throw CLI::RequiresError("--mesh", "--skeleton (only a .gltf/.glb rig brings its own)");
    }
    if (rig && (!source->skeleton_path.empty() || !source->weights_path.empty())) {
      throw CLI::ValidationError("--mesh",
                                 "a glTF rig brings its own skeleton and weights: give neither "
                                 "--skeleton nor --weights");
    }
  });
  options.mesh->excludes(options.phantom_vertices);
  options.rotation_blend = AddRotationBlendFlag(app, &source->rotation_blend);
  options.bone_surfaces =
      app.add_option("--bone-surface", source->bone_surfaces,
                     "A bone surface FILE:BONE to upload with --mesh (a closed mesh file, .obj "
                     ".ply .stl .off, carried by BONE: an index, HEAD-TAIL, or the joint it "
                     "starts at); repeatable")
          ->needs(options.mesh);
  app.add_flag("--phantom-without-bones", source->phantom_without_bones,
               "Load the phantom without its femur, tibia and patella")
      ->excludes(options.mesh);
  const auto on_off = [&app](const char* name, std::optional<bool>* value, const char* what) {
    app.add_option_function<std::string>(
           name, [value](const std::string& text) { *value = text == "on"; },
           std::string("on | off: ") + what + " (default: the server's, on)")
        ->check(CLI::IsMember({"on", "off"}));
  };
  on_off("--contacts", &source->contacts, "keep the skin outside the bone surfaces");
  on_off("--keep-volume", &source->keep_volume, "keep the skin's enclosed volume");
  return options;
}

std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv, const char* program) {
  app.set_version_flag("--version", VersionLine(program));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << program << ": " << e.what() << "\n";
    return 2;
  }
  return std::nullopt;
}

int ReportFailure(const char* program, const grpc::Status& status) {
  std::cerr << program << ": " << client::StatusText(status) << "\n";
  return 1;
}

grpc::Status WaitForServer(client::DeformClient& client, const ConnectionArgs& args) {
  if (client.WaitForReady(args.connect_timeout_ms)) return grpc::Status::OK;
  return grpc::Status(
      grpc::StatusCode::UNAVAILABLE,
      "cannot reach " + args.target + " within " + std::to_string(args.connect_timeout_ms) + " ms");
}

int RunOnAcquiredMesh(
    const char* program, const ConnectionArgs& connection, const MeshSource& source,
    const std::function<int(client::DeformClient&, const deform::v1::MeshSummary&)>& run_on_mesh,
    const std::function<bool(bool loaded)>& unload) {
  client::ClientOptions options;
  const grpc::Status configured = MakeClientOptions(connection.security, &options);
  if (!configured.ok()) return ReportFailure(program, configured);
  client::DeformClient client(connection.target, options);
  const grpc::Status connected = WaitForServer(client, connection);
  if (!connected.ok()) return ReportFailure(program, connected);
  deform::v1::MeshSummary summary;
  bool loaded = false;
  const grpc::Status acquired = AcquireMesh(client, source, &summary, &loaded);
  if (!acquired.ok()) return ReportFailure(program, acquired);
  const int code = run_on_mesh(client, summary);
  if (unload(loaded)) {
    // After a failed run the unload is best effort: the run's error is the one reported.
    const grpc::Status unloaded = client.UnloadMesh(summary.mesh_id());
    if (!unloaded.ok() && code == 0) return ReportFailure(program, unloaded);
  }
  return code;
}

}  // namespace deform::cli
