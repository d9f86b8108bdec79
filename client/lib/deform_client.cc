#include "deform_client.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>
#include <utility>

#include "deform_stream_impl.h"
#include "reconnecting_stream.h"

namespace deform::client {
namespace {

grpc::Status ReadWholeFile(const std::string& path, std::string* contents) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return grpc::Status(grpc::StatusCode::NOT_FOUND, "cannot open '" + path + "'");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return grpc::Status(grpc::StatusCode::NOT_FOUND, "cannot read '" + path + "'");
  *contents = std::move(buffer).str();
  return grpc::Status::OK;
}

bool EndsWithTgf(const std::string& path) {
  if (path.size() < 4) return false;
  std::string extension = path.substr(path.size() - 4);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".tgf";
}

std::string BaseName(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// The file name without its folder and extension.
std::string StemName(const std::string& path) {
  const std::string base = BaseName(path);
  const std::size_t dot = base.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? base : base.substr(0, dot);
}

void SetUnaryDeadline(const ClientOptions& options, grpc::ClientContext* context) {
  context->set_deadline(std::chrono::system_clock::now() +
                        std::chrono::milliseconds(options.unary_deadline_ms));
}

// Runs one LoadMesh call: sends `header` and the chunks of `mesh_bytes`, reads the progress.
grpc::Status RunLoadMesh(deform::v1::DeformService::Stub* stub, const ClientOptions& options,
                         const deform::v1::LoadMeshHeader& header, const std::string* mesh_bytes,
                         deform::v1::MeshSummary* summary, const ProgressCallback& progress) {
  grpc::ClientContext context;
  AddCallCredentials(options, &context);
  auto stream = stub->LoadMesh(&context);
  deform::v1::LoadMeshRequest request;
  *request.mutable_header() = header;
  bool writing = stream->Write(request);
  if (mesh_bytes != nullptr) {
    const std::size_t chunk = static_cast<std::size_t>(std::max(1, options.upload_chunk_bytes));
    for (std::size_t offset = 0; writing && offset < mesh_bytes->size(); offset += chunk) {
      request.set_chunk(mesh_bytes->substr(offset, chunk));
      writing = stream->Write(request);
    }
  }
  stream->WritesDone();
  deform::v1::LoadMeshResponse message;
  bool ready = false;
  while (stream->Read(&message)) {
    if (progress) progress(message);
    if (message.stage() == deform::v1::LoadMeshResponse::STAGE_READY) {
      ready = true;
      if (summary != nullptr) *summary = message.mesh();
    }
  }
  grpc::Status status = stream->Finish();
  if (status.ok() && !ready) {
    return grpc::Status(grpc::StatusCode::INTERNAL, "LoadMesh ended without a STAGE_READY message");
  }
  return status;
}

}  // namespace

grpc::Status LoadClientTlsFiles(const std::string& ca_file, const std::string& cert_file,
                                const std::string& key_file, ClientTls* tls) {
  if (cert_file.empty() != key_file.empty()) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        "a client certificate needs its key and a key its certificate");
  }
  tls->enabled = true;
  if (!ca_file.empty()) {
    const grpc::Status read = ReadWholeFile(ca_file, &tls->ca_pem);
    if (!read.ok()) return read;
  }
  if (!cert_file.empty()) {
    grpc::Status read = ReadWholeFile(cert_file, &tls->cert_pem);
    if (read.ok()) read = ReadWholeFile(key_file, &tls->key_pem);
    if (!read.ok()) return read;
  }
  return grpc::Status::OK;
}

std::shared_ptr<grpc::Channel> MakeDeformChannel(const std::string& target,
                                                 const ClientOptions& options) {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(options.max_receive_message_bytes);
  arguments.SetMaxSendMessageSize(-1);
  // A lost server is tried again within 100 ms to 1 s (gRPC's defaults: 1 s growing to 120 s),
  // so that a reconnecting stream (ReconnectPolicy) finds the next server soon.
  arguments.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, 100);
  arguments.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 100);
  arguments.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 1000);
  if (!options.tls.enabled) {
    return grpc::CreateCustomChannel(target, grpc::InsecureChannelCredentials(), arguments);
  }
  grpc::SslCredentialsOptions ssl;
  ssl.pem_root_certs = options.tls.ca_pem;
  ssl.pem_cert_chain = options.tls.cert_pem;
  ssl.pem_private_key = options.tls.key_pem;
  if (!options.tls.server_name.empty()) {
    arguments.SetSslTargetNameOverride(options.tls.server_name);
  }
  return grpc::CreateCustomChannel(target, grpc::SslCredentials(ssl), arguments);
}

void AddCallCredentials(const ClientOptions& options, grpc::ClientContext* context) {
  if (!options.token.empty()) context->AddMetadata("authorization", "Bearer " + options.token);
}

void AddMeshKey(const std::string& mesh_id, grpc::ClientContext* context) {
  constexpr std::size_t kMaxKeyBytes = 128;
  if (mesh_id.empty() || mesh_id.size() > kMaxKeyBytes) return;
  for (const char c : mesh_id) {
    if (c < 0x21 || c > 0x7e) return;  // gRPC refuses other metadata values
  }
  context->AddMetadata(kMeshKeyHeader, mesh_id);
}

DeformClient::DeformClient(const std::string& target, ClientOptions options)
    : DeformClient(MakeDeformChannel(target, options), options) {}

DeformClient::DeformClient(std::shared_ptr<grpc::Channel> channel, ClientOptions options)
    : channel_(std::move(channel)),
      stub_(deform::v1::DeformService::NewStub(channel_)),
      options_(options) {}

bool DeformClient::WaitForReady(int timeout_ms) {
  return channel_->WaitForConnected(std::chrono::system_clock::now() +
                                    std::chrono::milliseconds(timeout_ms));
}

grpc::Status DeformClient::LoadPhantom(int vertices, const deform::v1::MethodOptions& options,
                                       deform::v1::MeshSummary* summary,
                                       const ProgressCallback& progress, const std::string& name) {
  deform::v1::LoadMeshHeader header;
  header.set_name(name);
  header.mutable_phantom()->set_vertices(vertices);
  *header.mutable_options() = options;
  return RunLoadMesh(stub_.get(), options_, header, nullptr, summary, progress);
}

grpc::Status DeformClient::LoadMeshFiles(const std::string& mesh_path,
                                         const std::string& skeleton_path,
                                         const deform::v1::MethodOptions& options,
                                         deform::v1::MeshSummary* summary,
                                         const ProgressCallback& progress,
                                         const std::string& weights_path,
                                         const std::vector<std::string>& bone_surfaces) {
  deform::v1::LoadMeshHeader header;
  header.set_name(BaseName(mesh_path));
  *header.mutable_options() = options;
  deform::v1::UploadSource* upload = header.mutable_upload();
  upload->set_format(MeshFormatFromPath(mesh_path));
  if (upload->format() == deform::v1::MESH_FORMAT_UNSPECIFIED) {
    return grpc::Status(
        grpc::StatusCode::INVALID_ARGUMENT,
        "unknown mesh format for '" + mesh_path + "' (.obj .ply .stl .off, or a .gltf/.glb rig)");
  }
  std::string mesh_bytes;
  grpc::Status status = ReadWholeFile(mesh_path, &mesh_bytes);
  if (!status.ok()) return status;
  if (!skeleton_path.empty()) {
    status = ReadWholeFile(skeleton_path, upload->mutable_skeleton());
    if (!status.ok()) return status;
    upload->set_skeleton_format(EndsWithTgf(skeleton_path) ? deform::v1::SKELETON_FORMAT_TGF
                                                           : deform::v1::SKELETON_FORMAT_JSON);
  }
  if (!weights_path.empty()) {
    status = ReadWholeFile(weights_path, upload->mutable_weights());
    if (!status.ok()) return status;
    const bool csv =
        weights_path.size() >= 4 && weights_path.compare(weights_path.size() - 4, 4, ".csv") == 0;
    upload->set_weights_format(csv ? deform::v1::SKIN_WEIGHTS_FORMAT_CSV
                                   : deform::v1::SKIN_WEIGHTS_FORMAT_DMAT);
  }
  for (const std::string& spec : bone_surfaces) {
    status = AddBoneSurfaceFile(spec, upload);
    if (!status.ok()) return status;
  }
  return LoadMesh(header, mesh_bytes, summary, progress);
}

grpc::Status AddBoneSurfaceFile(const std::string& spec, deform::v1::UploadSource* upload) {
  const std::size_t colon = spec.find(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == spec.size()) {
    return grpc::Status(
        grpc::StatusCode::INVALID_ARGUMENT,
        "bone surface '" + spec + "' is not FILE:BONE (BONE a bone index, HEAD-TAIL or a joint)");
  }
  const std::string path = spec.substr(0, colon);
  const deform::v1::MeshFormat format = MeshFormatFromPath(path);
  if (format == deform::v1::MESH_FORMAT_UNSPECIFIED || format == deform::v1::MESH_FORMAT_GLTF) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        "unknown bone surface format for '" + path + "' (.obj .ply .stl .off)");
  }
  deform::v1::BoneSurfaceUpload surface;
  const grpc::Status read = ReadWholeFile(path, surface.mutable_mesh());
  if (!read.ok()) return read;
  surface.set_name(StemName(path));
  surface.set_format(format);
  surface.set_bone(spec.substr(colon + 1));
  *upload->add_bone_surfaces() = std::move(surface);
  return grpc::Status::OK;
}

grpc::Status DeformClient::LoadMesh(deform::v1::LoadMeshHeader header,
                                    const std::string& mesh_bytes, deform::v1::MeshSummary* summary,
                                    const ProgressCallback& progress) {
  if (header.has_phantom()) {
    return RunLoadMesh(stub_.get(), options_, header, nullptr, summary, progress);
  }
  header.mutable_upload()->set_mesh_size_bytes(mesh_bytes.size());
  return RunLoadMesh(stub_.get(), options_, header, &mesh_bytes, summary, progress);
}

grpc::Status DeformClient::LoadMeshBytes(const std::string& name, deform::v1::MeshFormat format,
                                         const std::string& mesh_bytes,
                                         deform::v1::SkeletonFormat skeleton_format,
                                         const std::string& skeleton_bytes,
                                         const deform::v1::MethodOptions& options,
                                         deform::v1::MeshSummary* summary,
                                         const ProgressCallback& progress) {
  deform::v1::LoadMeshHeader header;
  header.set_name(name);
  deform::v1::UploadSource* upload = header.mutable_upload();
  upload->set_format(format);
  upload->set_mesh_size_bytes(mesh_bytes.size());
  upload->set_skeleton_format(skeleton_format);
  upload->set_skeleton(skeleton_bytes);
  *header.mutable_options() = options;
  return RunLoadMesh(stub_.get(), options_, header, &mesh_bytes, summary, progress);
}

grpc::Status DeformClient::GetMeshInfo(const std::string& mesh_id, bool include_geometry,
                                       deform::v1::GetMeshInfoResponse* info) {
  deform::v1::GetMeshInfoRequest request;
  request.set_mesh_id(mesh_id);
  request.set_include_geometry(include_geometry);
  return GetMeshInfo(request, info);
}

grpc::Status DeformClient::GetMeshInfo(const deform::v1::GetMeshInfoRequest& request,
                                       deform::v1::GetMeshInfoResponse* info) {
  // A server still building the mesh (a cluster's replica, from the shared store) says when to
  // ask again (google.rpc.RetryInfo): asked again then, within the call's deadline.
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::milliseconds(options_.unary_deadline_ms);
  for (;;) {
    grpc::ClientContext context;
    SetUnaryDeadline(options_, &context);
    AddCallCredentials(options_, &context);
    AddMeshKey(request.mesh_id(), &context);
    const grpc::Status status = stub_->GetMeshInfo(&context, request, info);
    const int retry_ms = internal::RetryDelayMs(status);
    if (status.error_code() != grpc::StatusCode::UNAVAILABLE || retry_ms <= 0 ||
        std::chrono::steady_clock::now() + std::chrono::milliseconds(retry_ms) >= deadline) {
      return status;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(retry_ms));
  }
}

grpc::Status DeformClient::ListMeshes(std::vector<deform::v1::MeshSummary>* meshes) {
  grpc::ClientContext context;
  SetUnaryDeadline(options_, &context);
  AddCallCredentials(options_, &context);
  deform::v1::ListMeshesResponse response;
  const grpc::Status status =
      stub_->ListMeshes(&context, deform::v1::ListMeshesRequest(), &response);
  if (status.ok() && meshes != nullptr) {
    meshes->assign(response.meshes().begin(), response.meshes().end());
  }
  return status;
}

grpc::Status DeformClient::UnloadMesh(const std::string& mesh_id) {
  grpc::ClientContext context;
  SetUnaryDeadline(options_, &context);
  AddCallCredentials(options_, &context);
  AddMeshKey(mesh_id, &context);
  deform::v1::UnloadMeshRequest request;
  request.set_mesh_id(mesh_id);
  deform::v1::UnloadMeshResponse response;
  return stub_->UnloadMesh(&context, request, &response);
}

grpc::Status DeformClient::OpenContactQuery(const deform::v1::ContactQueryStart& start,
                                            std::unique_ptr<ContactQuery>* query) {
  auto context = std::make_unique<grpc::ClientContext>();
  AddCallCredentials(options_, context.get());
  AddMeshKey(start.mesh_id(), context.get());
  return ContactQuery::Open(stub_.get(), std::move(context), start, query);
}

std::unique_ptr<DeformStream> DeformClient::OpenStream(const std::string& mesh_id,
                                                       StreamCallbacks callbacks) {
  return OpenStream(mesh_id, std::move(callbacks), StreamOptions{});
}

std::unique_ptr<DeformStream> DeformClient::OpenStream(const std::string& mesh_id,
                                                       StreamCallbacks callbacks,
                                                       const StreamOptions& stream_options) {
  if (!stream_options.reconnect.enabled) {
    return OpenPlainStream(mesh_id, std::move(callbacks), stream_options, /*must_decode=*/false);
  }
  return internal::StartReconnectingStream(
      [this, mesh_id, stream_options](StreamCallbacks plain_callbacks) {
        return OpenPlainStream(mesh_id, std::move(plain_callbacks), stream_options,
                               /*must_decode=*/true);
      },
      std::move(callbacks), stream_options.reconnect);
}

std::unique_ptr<DeformStream> DeformClient::OpenPlainStream(const std::string& mesh_id,
                                                            StreamCallbacks callbacks,
                                                            const StreamOptions& stream_options,
                                                            bool must_decode) {
  deform::v1::DeformStart start;
  start.set_mesh_id(mesh_id);
  start.set_encoding(stream_options.encoding);
  start.set_max_error(stream_options.max_error);
  std::unique_ptr<codec::FrameDecoder> decoder;
  const bool predicted = stream_options.encoding == deform::v1::FRAME_ENCODING_PREDICTED;
  if (predicted || stream_options.encoding == deform::v1::FRAME_ENCODING_QUANTIZED) {
    deform::v1::GetMeshInfoRequest request;
    request.set_mesh_id(mesh_id);
    request.set_include_geometry(predicted);
    request.set_include_prediction_weights(predicted);
    deform::v1::GetMeshInfoResponse info;
    // An unknown mesh is answered by the stream itself (NOT_FOUND through on_done); a server that
    // cannot answer now is tried again by a reconnecting stream.
    const grpc::Status status = GetMeshInfo(request, &info);
    if (status.ok()) {
      decoder = internal::MakeFrameDecoder(info);
    } else if (must_decode && status.error_code() == grpc::StatusCode::UNAVAILABLE) {
      return nullptr;
    }
  }
  return internal::StartDeformStream(stub_.get(), options_, start, std::move(callbacks),
                                     std::move(decoder));
}

}  // namespace deform::client
