// The deformd client library: connect, load a mesh, open deform streams. Hides the gRPC stubs and
// the streaming reactor; exposes the deform.v1 messages themselves.
//
// Thread safety: DeformClient's methods may be called from any thread. A DeformStream's Send*
// methods may be called from any thread; its callbacks run on gRPC's threads, one at a time per
// stream, and must not block for long.
#pragma once

#include <grpcpp/grpcpp.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "contact_query.h"
#include "deform/v1/deform.grpc.pb.h"

namespace deform::client {

// TLS towards the server. PEM contents, not paths (LoadClientTlsFiles reads the files).
struct ClientTls {
  // Use TLS. Default: false (plaintext, which deformd serves on loopback addresses only unless
  // started with --plaintext).
  bool enabled = false;
  // The CA that signed the server's certificate; empty: the system's trusted roots.
  std::string ca_pem;
  // The client's own certificate chain and key, for a server that requires mutual TLS; empty:
  // none.
  std::string cert_pem;
  std::string key_pem;
  // The name the server's certificate must carry when it differs from the target's host (e.g.
  // connecting to an IP address). Default: the target's host.
  std::string server_name;
};

// Reads PEM files into `tls` (and sets tls->enabled): `ca_file` may be empty (system roots),
// `cert_file` and `key_file` both or neither. NOT_FOUND naming an unreadable file,
// INVALID_ARGUMENT for a certificate without its key or the reverse.
grpc::Status LoadClientTlsFiles(const std::string& ca_file, const std::string& cert_file,
                                const std::string& key_file, ClientTls* tls);

struct ClientOptions {
  // Largest message accepted (GetMeshInfo's geometry is 12 bytes per vertex and 12 per
  // triangle; a float32 frame 12 bytes per vertex). Default: 256 MiB.
  int max_receive_message_bytes = 256 << 20;
  // Upload chunk size for LoadMesh. Default: 1 MiB.
  int upload_chunk_bytes = 1 << 20;
  // Deadline of each unary call (GetMeshInfo, ListMeshes, UnloadMesh): DEADLINE_EXCEEDED after
  // this long. LoadMesh and Deform streams have none (a load's time grows with the mesh; a stream
  // lives as long as the session). Default: 30 s.
  int unary_deadline_ms = 30'000;
  // Transport security (above). Default: plaintext.
  ClientTls tls;
  // Bearer token sent with every call as the metadata "authorization: Bearer <token>" (a server
  // with a token file refuses calls without a valid one). Default: none.
  std::string token;
};

// The channel DeformClient(target, options) uses: TLS or plaintext, message limits, a lost
// connection tried again after 100 ms growing to at most 1 s. For other
// stubs on the same server (e.g. the health service).
std::shared_ptr<grpc::Channel> MakeDeformChannel(const std::string& target,
                                                 const ClientOptions& options);
// Adds options.token (if any) to `context` as "authorization: Bearer <token>".
void AddCallCredentials(const ClientOptions& options, grpc::ClientContext* context);

// The metadata every call that names a mesh carries, with the mesh's id (its content key), so that
// a balancer in front of several servers routes all of a mesh's calls to the one that holds it
// (docs/cluster.md). The library sets it on GetMeshInfo, UnloadMesh, Deform and QueryContact.
inline constexpr char kMeshKeyHeader[] = "deform-mesh-key";
// Adds `mesh_id` to `context` as kMeshKeyHeader (nothing for an id that is not printable ASCII of
// at most 128 bytes: such an id is no server's, and the call is answered NOT_FOUND unrouted).
void AddMeshKey(const std::string& mesh_id, grpc::ClientContext* context);

// How a Deform stream survives the loss of its server (a replica that died or drained, a mesh
// still being built on the replica the balancer chose): when the stream ends UNAVAILABLE (or
// CANCELLED without the application cancelling it: a balancer resets the streams of a server that
// died), the
// library opens it again on the same mesh after a backoff and re-sends the latest pose and the
// latest stiffness update; the application sees on_reconnect, then frames again, and on_done only
// when the stream really ends. Delays: the server's google.rpc.RetryInfo when it gives one, else
// initial_backoff_ms doubling up to max_backoff_ms (each with up to 20% jitter); it gives up, and
// on_done receives the UNAVAILABLE, once give_up_after_ms have passed since the stream last had a
// frame. Defaults: off.
struct ReconnectPolicy {
  bool enabled = false;
  int initial_backoff_ms = 50;
  int max_backoff_ms = 1000;
  int give_up_after_ms = 10'000;
};

using ProgressCallback = std::function<void(const deform::v1::LoadMeshResponse&)>;

class DeformStream;

class DeformClient {
 public:
  // Connects lazily to `target` ("host:port") through MakeDeformChannel(target, options).
  explicit DeformClient(const std::string& target, ClientOptions options = {});
  explicit DeformClient(std::shared_ptr<grpc::Channel> channel, ClientOptions options = {});

  // Waits up to `timeout_ms` for the channel to be ready. False on timeout.
  bool WaitForReady(int timeout_ms);

  // Loads the built-in knee phantom (`vertices` 0 = default). `summary` receives the READY summary.
  grpc::Status LoadPhantom(int vertices, const deform::v1::MethodOptions& options,
                           deform::v1::MeshSummary* summary, const ProgressCallback& progress = {},
                           const std::string& name = "phantom");
  // Uploads a mesh file and a skeleton file (formats from the extensions: .obj .ply .stl .off;
  // .tgf or JSON), and optionally the rig's skinning weights (.dmat, or .csv). A .gltf/.glb rig
  // carries skeleton and weights itself: give neither. `bone_surfaces`: "FILE:BONE" specs
  // (AddBoneSurfaceFile). Reading a file that does not exist gives NOT_FOUND without contacting
  // the server.
  grpc::Status LoadMeshFiles(const std::string& mesh_path, const std::string& skeleton_path,
                             const deform::v1::MethodOptions& options,
                             deform::v1::MeshSummary* summary,
                             const ProgressCallback& progress = {},
                             const std::string& weights_path = "",
                             const std::vector<std::string>& bone_surfaces = {});
  // Any upload: `header`'s upload (format, skeleton, weights, bone surfaces) and options as the
  // caller sets them; upload.mesh_size_bytes is set here from `mesh_bytes`. A header with a
  // phantom source (PhantomSource.without_bones, say) is sent as it is, `mesh_bytes` unused.
  grpc::Status LoadMesh(deform::v1::LoadMeshHeader header, const std::string& mesh_bytes,
                        deform::v1::MeshSummary* summary, const ProgressCallback& progress = {});
  // Uploads mesh bytes already in memory.
  grpc::Status LoadMeshBytes(const std::string& name, deform::v1::MeshFormat format,
                             const std::string& mesh_bytes,
                             deform::v1::SkeletonFormat skeleton_format,
                             const std::string& skeleton_bytes,
                             const deform::v1::MethodOptions& options,
                             deform::v1::MeshSummary* summary,
                             const ProgressCallback& progress = {});

  grpc::Status GetMeshInfo(const std::string& mesh_id, bool include_geometry,
                           deform::v1::GetMeshInfoResponse* info);
  grpc::Status ListMeshes(std::vector<deform::v1::MeshSummary>* meshes);
  grpc::Status UnloadMesh(const std::string& mesh_id);

  struct StreamCallbacks {
    std::function<void(const deform::v1::DeformFrame&)> on_frame;
    std::function<void(const deform::v1::Notice&)> on_notice;
    std::function<void(const grpc::Status&)> on_done;  // once, when the stream ends
    // With a ReconnectPolicy: the stream was lost with `lost` and has been opened again (its
    // `attempt`-th try since the last frame); frames follow from the new server.
    std::function<void(const grpc::Status& lost, int attempt)> on_reconnect;
  };
  // Opens a Deform stream on `mesh_id` (sends `start`). Errors such as NOT_FOUND arrive through
  // on_done / DeformStream::Wait().
  std::unique_ptr<DeformStream> OpenStream(const std::string& mesh_id, StreamCallbacks callbacks);

  // How a stream's frames travel (DeformStart.encoding, max_error). Whatever the encoding, the
  // library decodes every frame into DeformFrame.positions (float32 x, y, z per vertex, the mesh's
  // own vertex order) before on_frame; `encoded` stays as received (its size is what travelled).
  struct StreamOptions {
    deform::v1::FrameEncoding encoding = deform::v1::FRAME_ENCODING_FLOAT32;
    double max_error = 0;       // PREDICTED: fraction of the bounding-box diagonal; 0 = the default
    ReconnectPolicy reconnect;  // default: off (the first UNAVAILABLE ends the stream)
  };
  // As above with an encoding. For QUANTIZED and PREDICTED it first asks GetMeshInfo for what the
  // decoder needs (the vertex count; PREDICTED: the rest positions and prediction weights, once).
  // A frame that does not decode ends the stream with INTERNAL naming the problem. With
  // stream_options.reconnect the stream survives its server's loss (ReconnectPolicy); the
  // client must then outlive it.
  std::unique_ptr<DeformStream> OpenStream(const std::string& mesh_id, StreamCallbacks callbacks,
                                           const StreamOptions& stream_options);

  // Opens a QueryContact stream (contact_query.h) with `start` (the mesh, optionally a Deform
  // stream's id: DeformFrame.stream_id) and waits for the server's `started`.
  grpc::Status OpenContactQuery(const deform::v1::ContactQueryStart& start,
                                std::unique_ptr<ContactQuery>* query);
  // GetMeshInfo with every field of the request (prediction weights included).
  grpc::Status GetMeshInfo(const deform::v1::GetMeshInfoRequest& request,
                           deform::v1::GetMeshInfoResponse* info);

  deform::v1::DeformService::Stub* stub() { return stub_.get(); }

 private:
  // One Deform call; with `must_decode`, null when the decoder's GetMeshInfo was UNAVAILABLE.
  std::unique_ptr<DeformStream> OpenPlainStream(const std::string& mesh_id,
                                                StreamCallbacks callbacks,
                                                const StreamOptions& stream_options,
                                                bool must_decode);

  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<deform::v1::DeformService::Stub> stub_;
  ClientOptions options_;
};

// One bidirectional Deform stream. Writes are serialized: while one is in flight, a newer pose
// replaces any pose still waiting (latest wins), and stiffness updates queue in order.
class DeformStream {
 public:
  virtual ~DeformStream() = default;
  // False once the stream has ended or Close() was called.
  virtual bool SendPose(const deform::v1::PoseUpdate& pose) = 0;
  virtual bool SendStiffness(const deform::v1::StiffnessUpdate& stiffness) = 0;
  // Half-closes after the pending writes; the server then finishes the stream.
  virtual void Close() = 0;
  // Cancels the RPC now.
  virtual void Cancel() = 0;
  // Blocks until the stream has ended; returns its final status.
  virtual grpc::Status Wait() = 0;
};

// Client-side helpers.

// Adds the bone surface "FILE:BONE" to `upload` (the first ':' splits, so BONE may hold colons):
// the mesh file (.obj .ply .stl .off) carried by BONE (a bone index, HEAD-TAIL, or the joint it
// starts at; the server resolves it), named after the file. NOT_FOUND for an unreadable file,
// INVALID_ARGUMENT for a spec without both parts or an unknown extension.
grpc::Status AddBoneSurfaceFile(const std::string& spec, deform::v1::UploadSource* upload);

// A bone surface's rigid motion in a frame (DeformFrame.bone_transforms): posed = R rest + t.
struct BoneSurfaceMotion {
  float rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // row-major 3 x 3
  float translation[3] = {0, 0, 0};
};
// DeformFrame.bone_transforms decoded, one per bone surface (MeshSummary.bone_surfaces order);
// empty for a frame without bones or bytes that are not a whole number of transforms.
std::vector<BoneSurfaceMotion> DecodeBoneTransforms(const std::string& bytes);

// "JOINT:AXIS:DEGREES[,...]" (deformctl's syntax) into JointAngle terms; INVALID_ARGUMENT status
// in `error` (and false) for malformed text. Joint and axis names are checked by the server.
bool ParsePoseAngles(const std::string& spec, deform::v1::PoseUpdate* pose, std::string* error);
// A tool pressing the skin (docs/instruments.md) added to `pose`'s tools: a sphere, or a capsule
// from `center` to `end`; model units, the posed skin's frame. The server checks the values (and
// at most 4 tools a pose) and rejects the pose otherwise.
void AddSphereTool(double x, double y, double z, double radius, deform::v1::PoseUpdate* pose);
void AddCapsuleTool(const double center[3], const double end[3], double radius,
                    deform::v1::PoseUpdate* pose);
// "sphere:X,Y,Z,R" or "capsule:X0,Y0,Z0,X1,Y1,Z1,R" (deformctl's --tool) added to `pose`'s tools;
// INVALID_ARGUMENT status in `error` (and false, nothing added) for malformed text.
bool AddToolSpec(const std::string& spec, deform::v1::PoseUpdate* pose, std::string* error);
// float32 little-endian xyz bytes into floats (3 per vertex).
std::vector<float> DecodePositions(const std::string& bytes);
// Nanoseconds of a monotonic clock (for client_timestamp_ns and latency).
std::int64_t MonotonicNanos();
// Format from a file extension; MESH_FORMAT_UNSPECIFIED if unknown.
deform::v1::MeshFormat MeshFormatFromPath(const std::string& path);

}  // namespace deform::client
