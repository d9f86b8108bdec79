#include "service/contact/contact_query_reactor.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/constraints/tool_contact.h"
#include "core/model/deformation_model.h"
#include "service/access/audit_log.h"
#include "service/base/annotated_mutex.h"
#include "service/base/log_text.h"
#include "service/base/request_limits.h"
#include "service/base/self_owning_handler.h"
#include "service/base/thread_annotations.h"
#include "service/messages/proto_conversion.h"
#include "service/transport/status_mapping.h"
#include "service/transport/stream_write_pump.h"

namespace deform::service {
namespace {

void SetVector(const Eigen::Vector3d& v, v1::Vector3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}

class ContactQueryReactor final : public StreamHandler,
                                  public SelfOwningHandler<ContactQueryReactor>,
                                  private Drainable,
                                  private StreamWriteSource<v1::QueryContactResponse> {
 public:
  ContactQueryReactor(ServiceContext* context, Identity caller, ContactQueryTransport* transport)
      : context_(context),
        caller_(std::move(caller)),
        stream_id_(context->NextStreamId()),
        transport_(transport) {
    log_context_ =
        "contact stream=" + std::to_string(stream_id_) + " tenant=" + EscapeForLog(caller_.tenant);
    transport_->StartRead(&request_);
  }

  void OnReadDone(bool ok) DEFORM_EXCLUDES(mutex_) override;
  void OnWriteDone(bool ok) DEFORM_EXCLUDES(mutex_) override {
    MutexLock lock(&mutex_);
    pump_.OnWriteDone(ok);
  }
  void OnCancel() DEFORM_EXCLUDES(mutex_) override {
    FinishWith(grpc::StatusCode::CANCELLED, "cancelled by the client");
  }
  void OnDone() DEFORM_EXCLUDES(mutex_) override;

 private:
  // The start's checks and the stream's tree; an error status ends the stream.
  grpc::Status HandleStart() DEFORM_EXCLUDES(mutex_);
  Status StartChecked() DEFORM_EXCLUDES(mutex_);
  // The query's result into response_; INVALID_ARGUMENT for a bad tool.
  Status HandleQuery() DEFORM_EXCLUDES(mutex_);
  void FinishWith(grpc::StatusCode code, const std::string& message) DEFORM_EXCLUDES(mutex_);

  // Drainable.
  void Drain() DEFORM_EXCLUDES(mutex_) override {
    FinishWith(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
  }
  const Identity& caller() const override { return caller_; }
  void Revoke() DEFORM_EXCLUDES(mutex_) override {
    FinishWith(grpc::StatusCode::UNAUTHENTICATED, "the stream's token was revoked or changed");
  }

  // StreamWriteSource: the one response, when one is ready.
  const v1::QueryContactResponse* TakeNextWrite() override {
    mutex_.AssertHeld();
    if (!reply_ready_ || reply_taken_) return nullptr;
    reply_taken_ = true;
    return &response_;
  }
  void WriteCompleted(bool ok) override {
    mutex_.AssertHeld();
    reply_ready_ = reply_taken_ = false;
    if (ok && !pump_.finish_requested()) transport_->StartRead(&request_);
  }
  bool ReadyToFinish() override {
    mutex_.AssertHeld();
    return !reply_ready_;
  }

  ServiceContext* const context_;
  const Identity caller_;
  const std::uint64_t stream_id_;
  ContactQueryTransport* const transport_;
  std::string log_context_;

  // Set by HandleStart; then the reader's (one read, and so one query, at a time).
  std::shared_ptr<const MeshEntry> entry_;
  std::shared_ptr<const LatestFrame> frame_;  // null: the rest pose
  std::unique_ptr<SkinContactQuery> query_;
  ContactForceModel force_model_;
  Eigen::Vector3d tool_lower_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d tool_upper_ = Eigen::Vector3d::Zero();
  std::vector<double> staging_;   // a frame's positions, copied out of frame_ for the refit
  std::uint64_t tree_frame_ = 0;  // the frame the tree holds (0: the rest pose)
  std::uint64_t tree_sequence_ = 0;
  std::uint64_t queries_ = 0;
  bool attached_ = false;
  bool counted_ = false;
  bool registered_ = false;
  v1::QueryContactRequest request_;

  Mutex mutex_;
  v1::QueryContactResponse response_ DEFORM_GUARDED_BY(mutex_);
  bool reply_ready_ DEFORM_GUARDED_BY(mutex_) = false;
  bool reply_taken_ DEFORM_GUARDED_BY(mutex_) = false;
  Admission::MemoryHold memory_ DEFORM_GUARDED_BY(mutex_);
  StreamWritePump<v1::QueryContactResponse> pump_ DEFORM_GUARDED_BY(mutex_){
      this, transport_, FinishRule::kErrorOverridesGraceful};
};

void ContactQueryReactor::FinishWith(grpc::StatusCode code, const std::string& message) {
  MutexLock lock(&mutex_);
  if (code != grpc::StatusCode::OK) {
    spdlog::info("{} ending: {}", log_context_, EscapeControlBytes(BoundStatusMessage(message)));
  }
  pump_.RequestFinish(grpc::Status(code, BoundStatusMessage(message)));
  pump_.Pump();
}

void ContactQueryReactor::OnReadDone(bool ok) {
  if (!ok) {
    MutexLock lock(&mutex_);
    pump_.RequestFinish(grpc::Status::OK);
    pump_.Pump();
    return;
  }
  grpc::Status status;
  switch (request_.action_case()) {
    case v1::QueryContactRequest::kStart:
      status = query_ != nullptr ? grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                                "`start` sent twice on one stream")
                                 : HandleStart();
      break;
    case v1::QueryContactRequest::kQuery:
      status = query_ == nullptr ? grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                                "the first QueryContactRequest must be `start`")
                                 : ToGrpcStatus(HandleQuery());
      break;
    case v1::QueryContactRequest::ACTION_NOT_SET:
      status = grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                            "empty QueryContactRequest (no start or query)");
      break;
  }
  if (!status.ok()) {
    FinishWith(status.error_code(), status.error_message());
    return;
  }
  MutexLock lock(&mutex_);
  reply_ready_ = true;
  pump_.Pump();
}

grpc::Status ContactQueryReactor::HandleStart() {
  const Status checked = StartChecked();
  if (!checked.ok()) return ToGrpcStatus(checked);
  if (!context_->streams().Add(this)) {
    return grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
  }
  registered_ = true;
  // After Add: a reload that swapped the tokens before it is seen here, one after it revokes us.
  if (!context_->auth().StillValid(caller_)) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "unknown or revoked bearer token");
  }
  return grpc::Status::OK;
}

Status ContactQueryReactor::StartChecked() {
  const v1::ContactQueryStart& start = request_.start();
  const std::string& mesh_id = start.mesh_id();
  DEFORM_RETURN_IF_ERROR(CheckLength(mesh_id, kMaxMeshIdBytes, "start.mesh_id"));
  if (start.stiffness() != 0) force_model_.stiffness = start.stiffness();
  DEFORM_RETURN_IF_ERROR(ValidateContactForceModel(force_model_));
  auto entry = context_->FindMesh(mesh_id, caller_);
  if (!entry.ok()) {
    Audit(caller_.tenant, "contact", mesh_id, entry.status().ToString());
    return entry.status();
  }
  if (start.deform_stream_id() != 0) {
    auto frame = context_->latest_frames().Find(start.deform_stream_id(), caller_);
    if (!frame.ok() || (*frame)->mesh_id() != mesh_id) {
      const Status unknown =
          Status::NotFound("no open Deform stream " + std::to_string(start.deform_stream_id()) +
                           " on mesh " + mesh_id);
      Audit(caller_.tenant, "contact", mesh_id, unknown.ToString());
      return unknown;
    }
    frame_ = std::move(*frame);
  }
  DEFORM_RETURN_IF_ERROR(context_->registry().AttachStream(**entry));
  entry_ = std::move(*entry);
  attached_ = true;
  const Status quota = context_->admission().AcquireStream(caller_.tenant);
  Audit(caller_.tenant, "contact", mesh_id, quota.ok() ? "OK" : quota.ToString());
  DEFORM_RETURN_IF_ERROR(quota);
  counted_ = true;
  const DeformationModel& model = *entry_->model;
  const TriangleMesh& mesh = model.mesh();
  const std::size_t bytes = SkinContactQuery::BytesFor(mesh.num_vertices(), mesh.num_triangles()) +
                            (frame_ != nullptr ? LatestFrame::Bytes(mesh.num_vertices()) : 0);
  {
    MutexLock lock(&mutex_);
    memory_ = context_->admission().HoldMemory(caller_.tenant);
    DEFORM_RETURN_IF_ERROR(memory_.Resize(bytes, "a contact query's tree"));
  }
  const Eigen::VectorXd& squared = model.default_factorization()->row_weights_squared();
  std::vector<double> weights(mesh.num_vertices(), 1.0);
  for (int v = 0; v < mesh.num_vertices() && v < squared.size(); ++v) {
    weights[v] = std::sqrt(squared[v]);
  }
  auto query = SkinContactQuery::Create(mesh, std::move(weights));
  if (!query.ok()) return query.status();
  query_ = std::move(*query);
  if (frame_ != nullptr) staging_.assign(3 * static_cast<std::size_t>(mesh.num_vertices()), 0.0);
  tool_lower_ = mesh.vertices.colwise().minCoeff().transpose();
  tool_upper_ = mesh.vertices.colwise().maxCoeff().transpose();
  log_context_ += " mesh=" + entry_->id;
  if (frame_ != nullptr)
    log_context_ += " deform_stream=" + std::to_string(start.deform_stream_id());
  spdlog::info("{} opened: a tree of {} triangles, about {} KiB", log_context_,
               mesh.num_triangles(), bytes >> 10);
  MutexLock lock(&mutex_);
  v1::ContactQueryStarted* started = response_.mutable_started();
  started->set_bounding_box_diagonal(query_->rest_diagonal());
  started->set_stiffness(force_model_.stiffness);
  return Status::Ok();
}

Status ContactQueryReactor::HandleQuery() {
  const v1::ContactQuery& request = request_.query();
  Tool tool;
  const Status converted = ToolFromProto(request.tool(), 0, tool_lower_, tool_upper_, &tool);
  if (!converted.ok()) {
    return Status::InvalidArgument("query " + std::to_string(request.sequence()) + ": " +
                                   converted.message());
  }
  if (frame_ != nullptr &&
      frame_->CopyIfNewer(tree_frame_, staging_.data(), &tree_frame_, &tree_sequence_)) {
    query_->Refit(staging_.data());
  }
  const SkinContact contact = query_->Query(tool, force_model_);
  ++queries_;
  MutexLock lock(&mutex_);
  v1::ContactResult* result = response_.mutable_result();
  result->set_sequence(request.sequence());
  SetVector(contact.point, result->mutable_point());
  SetVector(contact.normal, result->mutable_normal());
  result->set_depth(contact.depth);
  SetVector(contact.force, result->mutable_force());
  result->set_signed_distance(contact.signed_distance);
  result->set_material_weight(contact.material_weight);
  result->set_frame_number(tree_frame_);
  result->set_frame_sequence(tree_sequence_);
  SetVector(contact.tool_point, result->mutable_tool_point());
  return Status::Ok();
}

void ContactQueryReactor::OnDone() {
  if (registered_) context_->streams().Remove(this);
  if (counted_) context_->admission().ReleaseStream(caller_.tenant);
  if (attached_) context_->registry().DetachStream(*entry_);
  {
    MutexLock lock(&mutex_);
    const grpc::Status& status = pump_.finish_status();
    spdlog::info("{} closed ({}): {} queries answered", log_context_,
                 status.ok() ? std::string("OK") : EscapeControlBytes(status.error_message()),
                 queries_);
  }
  ReleaseTransportReference();  // last: may free the reactor
}

}  // namespace

StreamHandler* NewContactQueryStream(ServiceContext* context, Identity caller,
                                     ContactQueryTransport* transport) {
  return ContactQueryReactor::Create(context, std::move(caller), transport);
}

}  // namespace deform::service
