#include "service/load/load_mesh_reactor.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <deque>
#include <string>
#include <utility>

#include "core/io/phantom.h"
#include "core/model/deformation_model.h"
#include "service/access/audit_log.h"
#include "service/base/annotated_mutex.h"
#include "service/base/log_text.h"
#include "service/base/self_owning_handler.h"
#include "service/base/thread_annotations.h"
#include "service/load/load_header.h"
#include "service/load/load_request.h"
#include "service/load/mesh_loader.h"
#include "service/messages/proto_conversion.h"
#include "service/registry/mesh_store.h"
#include "service/transport/status_mapping.h"
#include "service/transport/stream_write_pump.h"

namespace deform::service {
namespace {

using Clock = std::chrono::steady_clock;

// Bytes reserved up front for an upload; larger uploads grow as their chunks arrive.
constexpr std::size_t kMaxInitialReserve = std::size_t{64} << 20;

// What a load's header lets the server know of the memory it will need: a phantom's model
// (DeformationModel::EstimateBytesBeforeBuild, the phantom's triangles about twice its vertices);
// an upload's bytes as announced (mesh, skeleton, weights and bone surfaces), held while they
// arrive and are parsed.
std::size_t AdmissionBytes(const v1::LoadMeshHeader& header) {
  if (header.has_phantom()) {
    const int vertices =
        header.phantom().vertices() == 0 ? kDefaultPhantomVertices : header.phantom().vertices();
    return DeformationModel::EstimateBytesBeforeBuild(vertices, 2 * vertices);
  }
  const v1::UploadSource& upload = header.upload();
  return upload.mesh_size_bytes() + upload.skeleton().size() + upload.weights().size() +
         BoneSurfaceBytes(header);
}

std::string AdmissionSubject(const v1::LoadMeshHeader& header) {
  if (header.has_phantom()) {
    const int vertices =
        header.phantom().vertices() == 0 ? kDefaultPhantomVertices : header.phantom().vertices();
    return "a phantom of " + std::to_string(vertices) + " vertices";
  }
  return "an upload of " + std::to_string(AdmissionBytes(header)) + " bytes";
}

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

class LoadMeshReactor final : public StreamHandler,
                              public SelfOwningHandler<LoadMeshReactor>,
                              public ExpiringUpload,
                              private StreamWriteSource<v1::LoadMeshResponse> {
 public:
  LoadMeshReactor(ServiceContext* context, Identity caller, LoadMeshTransport* transport)
      : context_(context),
        caller_(std::move(caller)),
        transport_(transport),
        log_context_("load=" + std::to_string(context->NextLoadId()) +
                     " tenant=" + EscapeForLog(caller_.tenant)) {
    StartRead(&request_);
  }

  void OnReadDone(bool ok) DEFORM_EXCLUDES(mutex_) override;
  void OnWriteDone(bool ok) DEFORM_EXCLUDES(mutex_) override;
  void OnCancel() DEFORM_EXCLUDES(mutex_) override;
  void OnDone() override;
  // The upload stalled or took too long (upload_watchdog.h): DEADLINE_EXCEEDED.
  void ExpireUpload(const std::string& why) DEFORM_EXCLUDES(mutex_) override;

 private:
  Status HandleHeader();
  Status HandleChunk();
  Status HandleEndOfInput() DEFORM_EXCLUDES(mutex_);
  // On a worker: parse, validate, precompute, register.
  void Build() DEFORM_EXCLUDES(mutex_);
  StatusOr<std::shared_ptr<const MeshEntry>> ParseAndBuild() DEFORM_EXCLUDES(mutex_);

  void Fail(const Status& status) DEFORM_EXCLUDES(mutex_);
  void AddProgressLocked(v1::LoadMeshResponse::Stage stage, double elapsed_ms,
                         const MeshEntry* entry = nullptr) DEFORM_REQUIRES(mutex_);

  // StreamWriteSource: the progress messages in order; the pump calls these under mutex_.
  const v1::LoadMeshResponse* TakeNextWrite() override;
  void WriteCompleted(bool ok) override;
  bool ReadyToFinish() override { return true; }  // a finish is only requested when all is queued

  void StartRead(v1::LoadMeshRequest* request) { transport_->StartRead(request); }

  ServiceContext* const context_;
  const Identity caller_;
  LoadMeshTransport* const transport_;  // the pump's sink too; not used after its Finish()
  std::string log_context_;
  Clock::time_point start_;
  // The build's: cancelled by the client's cancel or a failed write, and at server shutdown.
  CancelToken cancel_{&context_->shutting_down()};

  // Reader-owned until the build is posted, then worker-owned.
  v1::LoadMeshRequest request_;
  v1::LoadMeshHeader header_;
  bool has_header_ = false;
  std::string mesh_bytes_;
  std::uint64_t expected_bytes_ = 0;
  Admission::MeshSlot reservation_;
  std::uint64_t upload_watch_ = 0;  // context_->uploads()' id while an upload arrives; 0: none
  // The load named a mesh loaded already (the same content): a cancel must not unload it.
  bool reused_ = false;

  Mutex mutex_;
  std::deque<v1::LoadMeshResponse> outbox_ DEFORM_GUARDED_BY(mutex_);
  v1::LoadMeshResponse in_flight_ DEFORM_GUARDED_BY(mutex_);
  bool cancelled_ DEFORM_GUARDED_BY(mutex_) = false;  // by the client, or a write failed
  StreamWritePump<v1::LoadMeshResponse> pump_ DEFORM_GUARDED_BY(mutex_){
      this, transport_, FinishRule::kFirstRequestWins};
};

void LoadMeshReactor::OnReadDone(bool ok) {
  Status status;
  if (!ok) {
    status = HandleEndOfInput();
  } else {
    switch (request_.part_case()) {
      case v1::LoadMeshRequest::kHeader:
        status = HandleHeader();
        break;
      case v1::LoadMeshRequest::kChunk:
        status = HandleChunk();
        break;
      case v1::LoadMeshRequest::PART_NOT_SET:
        status = Status::InvalidArgument("empty LoadMeshRequest (neither header nor chunk)");
        break;
    }
    if (status.ok()) {
      // Not after a finish (a cancel, a failed write or the upload watchdog on another thread):
      // the call is ending and its reads are over.
      MutexLock lock(&mutex_);
      if (!pump_.finish_requested()) StartRead(&request_);
    }
  }
  if (!status.ok()) Fail(status);
}

Status LoadMeshReactor::HandleHeader() {
  if (has_header_) {
    return Status::InvalidArgument("the header was sent twice").WithSubject("header");
  }
  start_ = Clock::now();
  header_.Swap(request_.mutable_header());
  has_header_ = true;
  DEFORM_RETURN_IF_ERROR(CheckLoadHeader(header_, context_->limits()));
  if (header_.has_phantom()) {
    const int vertices = header_.phantom().vertices();
    spdlog::info("{} phantom of {} vertices requested, name='{}'", log_context_,
                 vertices == 0 ? kDefaultPhantomVertices : vertices, EscapeForLog(header_.name()));
  } else {
    expected_bytes_ = header_.upload().mesh_size_bytes();
    upload_watch_ = context_->uploads().Watch(std::weak_ptr<LoadMeshReactor>(SharedFromThis()));
    mesh_bytes_.reserve(std::min<std::size_t>(expected_bytes_, kMaxInitialReserve));
    spdlog::info("{} upload of {} mesh bytes announced, name='{}'", log_context_, expected_bytes_,
                 EscapeForLog(header_.name()));
  }
  DEFORM_ASSIGN_OR_RETURN(reservation_, context_->admission().ReserveMesh(caller_.tenant));
  // Admission: the memory the load will need, as far as the header tells, is taken from the
  // budget before anything is allocated (BuildAndRegister replaces it by the model's estimate
  // once the upload is parsed).
  const Status admitted = context_->admission().ReserveMemory(
      &reservation_, AdmissionBytes(header_), AdmissionSubject(header_));
  if (!admitted.ok()) reservation_.Release();
  return admitted;
}

Status LoadMeshReactor::HandleChunk() {
  if (!has_header_) {
    return Status::InvalidArgument("the first LoadMeshRequest must be the header")
        .WithSubject("header");
  }
  if (header_.has_phantom()) {
    return Status::InvalidArgument("a phantom load takes no chunks").WithSubject("chunk");
  }
  const std::string& chunk = request_.chunk();
  if (mesh_bytes_.size() + chunk.size() > expected_bytes_) {
    return Status::InvalidArgument("the upload sent more than the " +
                                   std::to_string(expected_bytes_) +
                                   " mesh bytes announced in the header")
        .WithSubject("chunk");
  }
  mesh_bytes_.append(chunk);
  context_->uploads().Touch(upload_watch_);
  return Status::Ok();
}

Status LoadMeshReactor::HandleEndOfInput() {
  if (upload_watch_ != 0) context_->uploads().Forget(std::exchange(upload_watch_, 0));
  {
    MutexLock lock(&mutex_);
    if (pump_.finish_requested()) return Status::Ok();  // cancelled or already failed
  }
  if (!has_header_) {
    return Status::InvalidArgument("the stream ended without a header").WithSubject("header");
  }
  if (header_.has_upload() && mesh_bytes_.size() != expected_bytes_) {
    return Status::InvalidArgument(
               "truncated upload: received " + std::to_string(mesh_bytes_.size()) + " of the " +
               std::to_string(expected_bytes_) + " mesh bytes announced in the header")
        .WithSubject("chunk");
  }
  MutexLock lock(&mutex_);
  AddProgressLocked(v1::LoadMeshResponse::STAGE_RECEIVED, MillisecondsSince(start_));
  pump_.Pump();
  context_->pool().PostBackground([self = SharedFromThis()] { self->Build(); });
  return Status::Ok();
}

void LoadMeshReactor::Build() {
  bool skip;
  {
    MutexLock lock(&mutex_);
    skip = cancelled_ || pump_.finish_requested();
  }
  StatusOr<std::shared_ptr<const MeshEntry>> entry =
      skip ? StatusOr<std::shared_ptr<const MeshEntry>>(Status::FailedPrecondition("cancelled"))
           : ParseAndBuild();
  // A load refused before its build (declared size, parse) frees its slot and memory before the
  // client hears of it (the reactor may outlive the call a little).
  if (!entry.ok()) reservation_.Release();
  MutexLock lock(&mutex_);
  if (entry.ok()) {
    if (cancelled_ && !reused_) {
      // Nobody is waiting for it: the mesh would be unreachable.
      (void)context_->registry().Unload((*entry)->id);
      // An entry that cannot be deleted is logged; the mesh comes back at the next start.
      if (context_->store() != nullptr) (void)context_->store()->Remove((*entry)->id);
      Audit(caller_.tenant, "load", (*entry)->id, "CANCELLED");
    } else {
      Audit(caller_.tenant, "load", (*entry)->id, "OK");
      AddProgressLocked(v1::LoadMeshResponse::STAGE_READY, MillisecondsSince(start_), entry->get());
      pump_.RequestFinish(grpc::Status::OK);
    }
  } else if (!skip && cancel_.cancelled()) {
    // Stopped between two phases of the build; its memory and slot are released already.
    spdlog::info("{} build stopped: {}", log_context_, entry.status().message());
    Audit(caller_.tenant, "load", "", "CANCELLED");
    pump_.RequestFinish(context_->shutting_down().cancelled()
                            ? grpc::Status(grpc::StatusCode::UNAVAILABLE,
                                           "the server is shutting down: the load was stopped")
                            : grpc::Status(grpc::StatusCode::CANCELLED, "cancelled"));
  } else if (!skip) {
    spdlog::warn("{} failed: {}", log_context_, entry.status().ToString());
    Audit(caller_.tenant, "load", "", entry.status().ToString());
    pump_.RequestFinish(ToGrpcStatus(entry.status()));
  }
  pump_.Pump();
}

StatusOr<std::shared_ptr<const MeshEntry>> LoadMeshReactor::ParseAndBuild() {
  // Admission before parsing: what the file declares (its header's counts) must fit.
  std::string declared_subject;
  DEFORM_ASSIGN_OR_RETURN(
      const std::size_t declared,
      DeclaredLoadBytes(header_, mesh_bytes_, context_->limits(), &declared_subject));
  if (declared > reservation_.memory_bytes()) {
    DEFORM_RETURN_IF_ERROR(
        context_->admission().ReserveMemory(&reservation_, declared, declared_subject));
  }
  // The mesh's content key (mesh_key.h): the same content loaded again by this tenant is the
  // mesh loaded already, answered without a rebuild.
  const std::string key = context_->mesh_keys().KeyOf(caller_.tenant, header_, mesh_bytes_);
  {
    auto loaded = context_->registry().Find(key, caller_);
    if (loaded.ok()) {
      reused_ = true;
      reservation_.Release();
      spdlog::info("{} mesh={} is loaded already: the same content", log_context_, key);
      return loaded;
    }
  }
  MeshStore* const store = context_->store();
  std::string pending;
  // Kept on disk as uploaded (before parsing frees the bytes); committed once registered. A shared
  // store may hold it already (another replica's load): entries are immutable by key.
  const bool write_entry = store != nullptr && !store->Contains(key);
  if (write_entry) {
    DEFORM_ASSIGN_OR_RETURN(pending,
                            store->WritePending({key, caller_.tenant, header_, mesh_bytes_}));
  }
  StatusOr<LoadJob> parsed = LoadJobFromRequest(header_, &mesh_bytes_, context_->limits());
  if (!parsed.ok()) {
    if (write_entry) store->Discard(pending);
    return parsed.status();
  }
  LoadJob job = std::move(*parsed);
  job.start = start_;
  job.id = key;
  job.cancel = &cancel_;
  job.metrics = &context_->metrics();

  const auto progress = [this](LoadStage stage, double elapsed_ms) {
    MutexLock lock(&mutex_);
    switch (stage) {
      case LoadStage::kValidated:
        AddProgressLocked(v1::LoadMeshResponse::STAGE_VALIDATED, elapsed_ms);
        break;
      case LoadStage::kWeights:
        AddProgressLocked(v1::LoadMeshResponse::STAGE_WEIGHTS, elapsed_ms);
        break;
      case LoadStage::kFactorized:
        AddProgressLocked(v1::LoadMeshResponse::STAGE_FACTORISED, elapsed_ms);
        break;
    }
    pump_.Pump();
  };
  auto entry = BuildAndRegister(context_, std::move(reservation_), std::move(job), progress);
  if (!entry.ok()) {
    if (write_entry) store->Discard(pending);
    // The same content loaded at the same time by another call of this tenant: that mesh.
    auto loaded = context_->registry().Find(key, caller_);
    if (loaded.ok()) {
      reused_ = true;
      return loaded;
    }
    return entry;
  }
  if (write_entry) store->Commit(pending, key);
  if (store != nullptr) context_->MarkStored(key);
  return entry;
}

void LoadMeshReactor::Fail(const Status& status) {
  if (upload_watch_ != 0) context_->uploads().Forget(std::exchange(upload_watch_, 0));
  spdlog::warn("{} refused: {}", log_context_, status.ToString());
  Audit(caller_.tenant, "load", "", status.ToString());
  MutexLock lock(&mutex_);
  pump_.RequestFinish(ToGrpcStatus(status));
  pump_.Pump();
}

void LoadMeshReactor::AddProgressLocked(v1::LoadMeshResponse::Stage stage, double elapsed_ms,
                                        const MeshEntry* entry) {
  v1::LoadMeshResponse& progress = outbox_.emplace_back();
  progress.set_stage(stage);
  progress.set_elapsed_ms(elapsed_ms);
  if (entry != nullptr) FillMeshSummary(*entry, progress.mutable_mesh());
}

const v1::LoadMeshResponse* LoadMeshReactor::TakeNextWrite() {
  mutex_.AssertHeld();
  if (outbox_.empty()) return nullptr;
  in_flight_.Swap(&outbox_.front());
  outbox_.pop_front();
  return &in_flight_;
}

void LoadMeshReactor::WriteCompleted(bool ok) {
  mutex_.AssertHeld();
  if (!ok) {
    cancelled_ = true;
    cancel_.Cancel();
  }
}

void LoadMeshReactor::OnWriteDone(bool ok) {
  MutexLock lock(&mutex_);
  pump_.OnWriteDone(ok);
}

void LoadMeshReactor::OnCancel() {
  cancel_.Cancel();  // a build in progress stops at the end of its phase
  MutexLock lock(&mutex_);
  cancelled_ = true;
  pump_.RequestFinish(grpc::Status(grpc::StatusCode::CANCELLED, "cancelled by the client"));
  pump_.Pump();
}

void LoadMeshReactor::ExpireUpload(const std::string& why) {
  {
    MutexLock lock(&mutex_);
    if (pump_.finish_requested()) return;  // ended already (failed or cancelled)
  }
  spdlog::warn("{} upload ended: {}", log_context_, why);
  Audit(caller_.tenant, "load", "", "DEADLINE_EXCEEDED");
  MutexLock lock(&mutex_);
  pump_.RequestFinish(grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, why));
  pump_.Pump();
}

void LoadMeshReactor::OnDone() {
  ReleaseTransportReference();  // last: may free the reactor
}

}  // namespace

StreamHandler* NewLoadMeshStream(ServiceContext* context, Identity caller,
                                 LoadMeshTransport* transport) {
  return LoadMeshReactor::Create(context, std::move(caller), transport);
}

}  // namespace deform::service
