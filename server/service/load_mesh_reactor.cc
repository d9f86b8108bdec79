#include "service/load_mesh_reactor.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <utility>

#include "core/geometry/skeleton.h"
#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"
#include "service/mesh_loader.h"
#include "service/proto_conversion.h"
#include "service/shared_reactor.h"
#include "service/status_mapping.h"

namespace deform::service {
namespace {

using Clock = std::chrono::steady_clock;

// Bytes reserved up front for an upload; larger uploads grow as their chunks arrive.
constexpr std::size_t kMaxInitialReserve = std::size_t{64} << 20;

StatusOr<MeshFormat> CoreMeshFormat(v1::MeshFormat format) {
  switch (format) {
    case v1::MESH_FORMAT_OBJ:
      return MeshFormat::kObj;
    case v1::MESH_FORMAT_PLY:
      return MeshFormat::kPly;
    case v1::MESH_FORMAT_STL:
      return MeshFormat::kStl;
    case v1::MESH_FORMAT_OFF:
      return MeshFormat::kOff;
    default:
      return Status::InvalidArgument("upload.format is unspecified or unknown (" +
                                     std::to_string(static_cast<int>(format)) + ")");
  }
}

StatusOr<Skeleton> ParseSkeleton(v1::SkeletonFormat format, const std::string& bytes) {
  switch (format) {
    case v1::SKELETON_FORMAT_TGF:
      return ParseTgf(bytes);
    case v1::SKELETON_FORMAT_JSON:
      return ParseSkeletonJson(bytes);
    default:
      return Status::InvalidArgument("upload.skeleton_format is unspecified or unknown (" +
                                     std::to_string(static_cast<int>(format)) + ")");
  }
}

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

class LoadMeshReactor final
    : public grpc::ServerBidiReactor<v1::LoadMeshRequest, v1::LoadMeshResponse>,
      public SharedReactor<LoadMeshReactor> {
 public:
  explicit LoadMeshReactor(ServiceCore* core)
      : core_(core), log_context_("load=" + std::to_string(core->next_load_id.fetch_add(1))) {
    StartRead(&request_);
  }

  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnCancel() override;
  void OnDone() override;

 private:
  Status HandleHeader();
  Status HandleChunk();
  Status HandleEndOfInput();
  // On a worker: parse, validate, precompute, register.
  void Build();
  StatusOr<std::shared_ptr<const MeshEntry>> ParseAndBuild();

  void Fail(const Status& status);
  // Require mutex_.
  void AddProgressLocked(v1::LoadMeshResponse::Stage stage, double elapsed_ms,
                         const MeshEntry* entry = nullptr);
  void RequestFinishLocked(const grpc::Status& status);
  void PumpLocked();

  ServiceCore* const core_;
  std::string log_context_;
  Clock::time_point start_;

  // Reader-owned until the build is posted, then worker-owned.
  v1::LoadMeshRequest request_;
  v1::LoadMeshHeader header_;
  bool has_header_ = false;
  std::string mesh_bytes_;
  std::uint64_t expected_bytes_ = 0;
  MeshRegistry::Reservation reservation_;

  std::mutex mutex_;
  // Guarded by mutex_.
  std::deque<v1::LoadMeshResponse> outbox_;
  v1::LoadMeshResponse in_flight_;
  bool write_in_flight_ = false;
  bool finish_requested_ = false;
  bool finish_called_ = false;
  bool cancelled_ = false;
  grpc::Status finish_status_;
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
    if (status.ok()) StartRead(&request_);
  }
  if (!status.ok()) Fail(status);
}

Status LoadMeshReactor::HandleHeader() {
  if (has_header_) return Status::InvalidArgument("the header was sent twice");
  start_ = Clock::now();
  header_.Swap(request_.mutable_header());
  has_header_ = true;
  const ServiceLimits& limits = core_->limits;
  switch (header_.source_case()) {
    case v1::LoadMeshHeader::kPhantom: {
      const int vertices = header_.phantom().vertices();
      if (vertices < 0) {
        return Status::InvalidArgument("phantom.vertices must not be negative, got " +
                                       std::to_string(vertices));
      }
      const int effective = vertices == 0 ? kDefaultPhantomVertices : vertices;
      if (static_cast<std::size_t>(effective) > limits.max_vertices) {
        return Status::ResourceExhausted(
            "a phantom of " + std::to_string(effective) + " vertices exceeds the limit of " +
            std::to_string(limits.max_vertices) + " vertices per mesh");
      }
      spdlog::info("{} phantom of {} vertices requested, name='{}'", log_context_, effective,
                   header_.name());
      break;
    }
    case v1::LoadMeshHeader::kUpload: {
      const v1::UploadSource& upload = header_.upload();
      DEFORM_RETURN_IF_ERROR(CoreMeshFormat(upload.format()).status());
      if (upload.mesh_size_bytes() == 0) {
        return Status::InvalidArgument("upload.mesh_bytes is 0: the mesh file size is required");
      }
      if (upload.skeleton().empty()) return Status::InvalidArgument("upload.skeleton is empty");
      if (upload.skeleton_format() != v1::SKELETON_FORMAT_TGF &&
          upload.skeleton_format() != v1::SKELETON_FORMAT_JSON) {
        return Status::InvalidArgument("upload.skeleton_format is unspecified or unknown");
      }
      const std::uint64_t total = upload.mesh_size_bytes() + upload.skeleton().size();
      if (upload.mesh_size_bytes() > limits.max_upload_bytes || total > limits.max_upload_bytes) {
        return Status::ResourceExhausted("upload of " + std::to_string(total) +
                                         " bytes exceeds the limit of " +
                                         std::to_string(limits.max_upload_bytes) + " bytes");
      }
      expected_bytes_ = upload.mesh_size_bytes();
      mesh_bytes_.reserve(std::min<std::size_t>(expected_bytes_, kMaxInitialReserve));
      spdlog::info("{} upload of {} mesh bytes announced, name='{}'", log_context_, expected_bytes_,
                   header_.name());
      break;
    }
    case v1::LoadMeshHeader::SOURCE_NOT_SET:
      return Status::InvalidArgument("the header names no source (phantom or upload)");
  }
  DEFORM_ASSIGN_OR_RETURN(reservation_, core_->registry.Reserve());
  return Status::Ok();
}

Status LoadMeshReactor::HandleChunk() {
  if (!has_header_) return Status::InvalidArgument("the first LoadMeshRequest must be the header");
  if (header_.has_phantom()) return Status::InvalidArgument("a phantom load takes no chunks");
  const std::string& chunk = request_.chunk();
  if (mesh_bytes_.size() + chunk.size() > expected_bytes_) {
    return Status::InvalidArgument("the upload sent more than the " +
                                   std::to_string(expected_bytes_) +
                                   " mesh bytes announced in the header");
  }
  mesh_bytes_.append(chunk);
  return Status::Ok();
}

Status LoadMeshReactor::HandleEndOfInput() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finish_requested_) return Status::Ok();  // cancelled or already failed
  }
  if (!has_header_) return Status::InvalidArgument("the stream ended without a header");
  if (header_.has_upload() && mesh_bytes_.size() != expected_bytes_) {
    return Status::InvalidArgument(
        "truncated upload: received " + std::to_string(mesh_bytes_.size()) + " of the " +
        std::to_string(expected_bytes_) + " mesh bytes announced in the header");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  AddProgressLocked(v1::LoadMeshResponse::STAGE_RECEIVED, MillisecondsSince(start_));
  PumpLocked();
  core_->pool.PostBackground([self = SharedFromThis()] { self->Build(); });
  return Status::Ok();
}

void LoadMeshReactor::Build() {
  bool skip;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    skip = cancelled_ || finish_requested_;
  }
  StatusOr<std::shared_ptr<const MeshEntry>> entry =
      skip ? StatusOr<std::shared_ptr<const MeshEntry>>(Status::FailedPrecondition("cancelled"))
           : ParseAndBuild();
  std::lock_guard<std::mutex> lock(mutex_);
  if (entry.ok()) {
    if (cancelled_) {
      // Nobody is waiting for it: the mesh would be unreachable.
      (void)core_->registry.Unload((*entry)->id);
    } else {
      AddProgressLocked(v1::LoadMeshResponse::STAGE_READY, MillisecondsSince(start_), entry->get());
      RequestFinishLocked(grpc::Status::OK);
    }
  } else if (!skip) {
    spdlog::warn("{} failed: {}", log_context_, entry.status().ToString());
    RequestFinishLocked(ToGrpcStatus(entry.status()));
  }
  PumpLocked();
}

StatusOr<std::shared_ptr<const MeshEntry>> LoadMeshReactor::ParseAndBuild() {
  LoadJob job;
  job.start = start_;
  job.name = header_.name();
  if (header_.has_phantom()) {
    const int vertices =
        header_.phantom().vertices() == 0 ? kDefaultPhantomVertices : header_.phantom().vertices();
    DEFORM_ASSIGN_OR_RETURN(KneePhantom phantom, MakeKneePhantom(vertices));
    job.mesh = std::move(phantom.mesh);
    job.skeleton = std::move(phantom.skeleton);
    if (job.name.empty()) job.name = "phantom:" + std::to_string(vertices);
  } else {
    const v1::UploadSource& upload = header_.upload();
    DEFORM_ASSIGN_OR_RETURN(const MeshFormat format, CoreMeshFormat(upload.format()));
    MeshLimits limits;
    limits.max_vertices = core_->limits.max_vertices;
    auto mesh = ReadMesh(mesh_bytes_, format, limits);
    if (!mesh.ok()) return mesh.status().WithContext("mesh");
    job.mesh = std::move(*mesh);
    std::string().swap(mesh_bytes_);  // the bytes are no longer needed
    auto skeleton = ParseSkeleton(upload.skeleton_format(), upload.skeleton());
    if (!skeleton.ok()) return skeleton.status().WithContext("skeleton");
    job.skeleton = std::move(*skeleton);
    if (job.name.empty()) job.name = "upload";
  }
  auto options = ModelOptionsFromProto(header_.options(), job.skeleton);
  if (!options.ok()) return options.status().WithContext("options");
  job.options = std::move(*options);

  const auto progress = [this](LoadStage stage, double elapsed_ms) {
    std::lock_guard<std::mutex> lock(mutex_);
    switch (stage) {
      case LoadStage::kValidated:
        AddProgressLocked(v1::LoadMeshResponse::STAGE_VALIDATED, elapsed_ms);
        break;
      case LoadStage::kWeights:
        AddProgressLocked(v1::LoadMeshResponse::STAGE_WEIGHTS, elapsed_ms);
        break;
      case LoadStage::kFactorised:
        AddProgressLocked(v1::LoadMeshResponse::STAGE_FACTORISED, elapsed_ms);
        break;
    }
    PumpLocked();
  };
  return BuildAndRegister(&core_->registry, std::move(reservation_), std::move(job), progress);
}

void LoadMeshReactor::Fail(const Status& status) {
  spdlog::warn("{} refused: {}", log_context_, status.ToString());
  std::lock_guard<std::mutex> lock(mutex_);
  RequestFinishLocked(ToGrpcStatus(status));
  PumpLocked();
}

void LoadMeshReactor::AddProgressLocked(v1::LoadMeshResponse::Stage stage, double elapsed_ms,
                                        const MeshEntry* entry) {
  v1::LoadMeshResponse& progress = outbox_.emplace_back();
  progress.set_stage(stage);
  progress.set_elapsed_ms(elapsed_ms);
  if (entry != nullptr) FillMeshSummary(*entry, progress.mutable_mesh());
}

void LoadMeshReactor::RequestFinishLocked(const grpc::Status& status) {
  if (finish_requested_) return;
  finish_requested_ = true;
  finish_status_ = status;
}

void LoadMeshReactor::PumpLocked() {
  if (finish_called_ || write_in_flight_) return;
  if (finish_requested_ && !finish_status_.ok()) {
    finish_called_ = true;
    Finish(finish_status_);
    return;
  }
  if (!outbox_.empty()) {
    in_flight_.Swap(&outbox_.front());
    outbox_.pop_front();
    write_in_flight_ = true;
    StartWrite(&in_flight_);
    return;
  }
  if (finish_requested_) {
    finish_called_ = true;
    Finish(finish_status_);
  }
}

void LoadMeshReactor::OnWriteDone(bool ok) {
  std::lock_guard<std::mutex> lock(mutex_);
  write_in_flight_ = false;
  if (!ok) {
    cancelled_ = true;
    RequestFinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "write failed"));
  }
  PumpLocked();
}

void LoadMeshReactor::OnCancel() {
  std::lock_guard<std::mutex> lock(mutex_);
  cancelled_ = true;
  RequestFinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "cancelled by the client"));
  PumpLocked();
}

void LoadMeshReactor::OnDone() {
  ReleaseTransportReference();  // last: may free the reactor
}

}  // namespace

grpc::ServerBidiReactor<v1::LoadMeshRequest, v1::LoadMeshResponse>* NewLoadMeshReactor(
    ServiceCore* core) {
  return LoadMeshReactor::Create(core);
}

}  // namespace deform::service
