#include "service/deform/deform_stream_reactor.h"

#include <spdlog/spdlog.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "core/model/deformation_model.h"
#include "service/access/audit_log.h"
#include "service/base/annotated_mutex.h"
#include "service/base/log_text.h"
#include "service/base/request_limits.h"
#include "service/base/self_owning_handler.h"
#include "service/base/thread_annotations.h"
#include "service/deform/deform_outbox.h"
#include "service/deform/frame_solver.h"
#include "service/deform/pending_pose_slot.h"
#include "service/deform/pose_input.h"
#include "service/deform/stiffness_switch.h"
#include "service/messages/frame_encoding.h"
#include "service/messages/proto_conversion.h"
#include "service/transport/status_mapping.h"
#include "service/transport/stream_write_pump.h"
#include "service/workers/worker_pool.h"
#include "service/workers/worker_pool_parallel_runner.h"

namespace deform::service {
namespace {

using Clock = std::chrono::steady_clock;

// Counts a message whose write completed (what the client received) in `metrics`.
void CountWritten(const v1::DeformResponse& message, ServiceMetrics* metrics) {
  if (message.has_notice()) {
    metrics->NoticeWritten(message.notice().kind());
    return;
  }
  if (!message.has_frame()) return;
  const v1::DeformFrame& frame = message.frame();
  const v1::FrameTimings& t = frame.timings();
  // The frame's own timings split its server time: the wait before its solve, and the rest.
  const double compute_ms = t.rhs_ms() + t.solve_ms() + t.constraint_ms() + t.encode_ms();
  const int encoding =
      frame.has_encoded() ? frame.encoded().encoding() : v1::FRAME_ENCODING_FLOAT32;
  metrics->FrameWritten(encoding, message.ByteSizeLong(), t.queue_ms() * 1e-3, compute_ms * 1e-3,
                        frame.skipped_poses());
  if (frame.has_constraints()) {
    metrics->ConstrainedFrameWritten(t.constraint_ms() * 1e-3, frame.constraints().unresolved());
  }
}

// The reactor coordinates the stream's parts; each part states its own contract:
//  PendingPoseSlot (latest wins, skipped poses, the solve task's state), StiffnessSwitch (the
//  factorization in use and the refactorizations), DeformOutbox (notices and frame slots, in
//  order), StreamWritePump (one write in flight, the finish), FrameSolver (the solve itself).
// The first four are guarded by mutex_; the solver and the pose it solves belong to the solve
// task, the request buffers to the reader (one read outstanding at a time).
class DeformStreamReactor final : public StreamHandler,
                                  public SelfOwningHandler<DeformStreamReactor>,
                                  public FrameTask,
                                  private Drainable,
                                  private StreamWriteSource<v1::DeformResponse> {
 public:
  DeformStreamReactor(ServiceContext* context, Identity caller, DeformTransport* transport)
      : context_(context),
        caller_(std::move(caller)),
        stream_id_(context->NextStreamId()),
        transport_(transport) {
    log_context_ =
        "stream=" + std::to_string(stream_id_) + " tenant=" + EscapeForLog(caller_.tenant);
    outbox_.set_backlog_gauge(&context->notice_backlog_bytes());
    StartRead(&request_);
  }

  void OnReadDone(bool ok) DEFORM_EXCLUDES(mutex_) override;
  void OnWriteDone(bool ok) DEFORM_EXCLUDES(mutex_) override;
  void OnCancel() DEFORM_EXCLUDES(mutex_) override;
  void OnDone() DEFORM_EXCLUDES(mutex_) override;

 private:
  // Reactions' helpers (gRPC threads).
  void HandleStart() DEFORM_EXCLUDES(mutex_);
  void HandlePose() DEFORM_EXCLUDES(mutex_);
  // The pose request's tools into staging_ (ToolsFromProto); INVALID_ARGUMENT for tools on a
  // mesh whose constraints take none.
  Status StagedTools();
  void HandleStiffness() DEFORM_EXCLUDES(mutex_);
  void Fail(grpc::StatusCode code, const std::string& message) DEFORM_EXCLUDES(mutex_);
  void FailLocked(grpc::StatusCode code, const std::string& message) DEFORM_REQUIRES(mutex_);
  // As above with a core status, which keeps its error details (status_mapping.h).
  void Fail(const Status& status) DEFORM_EXCLUDES(mutex_);
  void FailLocked(const Status& status) DEFORM_REQUIRES(mutex_);
  // Reads the next request, or stops reading while the notice backlog is full (a client that
  // sends without reading); WriteCompleted resumes once it has drained.
  void ReadNextLocked() DEFORM_REQUIRES(mutex_);
  // The notices of a stiffness update that will not be applied: refused (`why`, also logged), or
  // replaced by a newer version `by` (`when`: at which step).
  void RejectStiffnessLocked(std::uint64_t version, const std::string& why) DEFORM_REQUIRES(mutex_);
  void SupersedeStiffnessLocked(std::uint64_t superseded, std::uint64_t by, const char* when)
      DEFORM_REQUIRES(mutex_);

  // FrameTask: the stream's solve on a worker, alone or batched with other streams' on the same
  // factorization (the pool gathers streams whose BatchKey, their factorization, is the same).
  void RunUrgent() DEFORM_EXCLUDES(mutex_) override;
  void RunUrgentBatch(FrameTask* const* others, int count) DEFORM_EXCLUDES(mutex_) override;
  const void* BatchKey() const override { return batch_key_.load(std::memory_order_relaxed); }
  // A mesh with a parallel plan: its batches (and lone frames) split over the idle workers.
  bool SplitsItsBatches() const override { return splits_batches_.load(std::memory_order_relaxed); }
  // A run's steps for one stream: BeginSolveRun takes the pending pose into solving_ with its
  // factorization, stamp and frame (false: nothing to solve); RejectSolvingPose answers a pose the
  // solver refused with a notice; EndSolveRun publishes the frame (`produced`), switches in a
  // finished refactorization and ends the run, posting the task again when a pose is pending.
  // Every BeginSolveRun is followed by one EndSolveRun.
  bool BeginSolveRun() DEFORM_EXCLUDES(mutex_);
  void RejectSolvingPose(const Status& status) DEFORM_EXCLUDES(mutex_);
  void EndSolveRun(bool produced) DEFORM_EXCLUDES(mutex_);
  // The batch key of the stream's current factorization: itself, or null (never batched) when it
  // evaluates a linear response, which shares nothing.
  void UpdateBatchKeyLocked() DEFORM_REQUIRES(mutex_);
  // Drainable.
  void Drain() DEFORM_EXCLUDES(mutex_) override;
  const Identity& caller() const override { return caller_; }
  void Revoke() DEFORM_EXCLUDES(mutex_) override;
  // The end of a revoked stream: UNAUTHENTICATED (after its notice, or at once without one).
  void FinishRevokedLocked() DEFORM_REQUIRES(mutex_);

  // Posts the background refactorization of `update`, once the memory budgets hold its
  // factorization (else KIND_STIFFNESS_REJECTED naming the budget).
  void StartRefactorLocked(StiffnessSwitch::Update update) DEFORM_REQUIRES(mutex_);
  // Makes memory_ hold the buffers and one factorization's bytes for each factorization of the
  // stream's own that may be alive: the current one unless it is the model's default, the next
  // one waiting to be switched in, and `running` being built.
  Status HoldFactorizationsLocked(int running, const std::string& what) DEFORM_REQUIRES(mutex_);
  // On a worker: the refactorization, then its result handed to the stream.
  void Refactor(const StiffnessSwitch::Update& update) DEFORM_EXCLUDES(mutex_);
  // Switches the finished factorization in, with its KIND_STIFFNESS_APPLIED notice. Only between
  // two solves.
  void ApplyNextFactorizationLocked() DEFORM_REQUIRES(mutex_);

  // StreamWriteSource: the outbox's messages; the pump calls these under mutex_.
  const v1::DeformResponse* TakeNextWrite() override;
  void WriteCompleted(bool ok) override;
  bool ReadyToFinish() override;

  void StartRead(v1::DeformRequest* request) { transport_->StartRead(request); }

  ServiceContext* const context_;
  const Identity caller_;
  const std::uint64_t stream_id_;
  DeformTransport* const transport_;  // the pump's sink too; not used after its Finish()
  std::string log_context_;           // "stream=N tenant=T mesh=ID", for logs

  // Set by HandleStart before any worker can see the stream; read-only afterwards.
  std::shared_ptr<const MeshEntry> entry_;
  const DeformationModel* model_ = nullptr;  // non-null once started
  bool registered_ = false;                  // in context_->streams()
  // The latest solved frame, for contact queries (context_->latest_frames(), under stream_id_);
  // set by HandleStart before any solve, published by the solve task.
  std::shared_ptr<LatestFrame> latest_;
  bool counted_ = false;  // in context_->admission()'s streams

  // Reader-owned (one read outstanding at a time).
  v1::DeformRequest request_;
  PoseInput staging_;
  // The rest mesh's bounding box, which tools are checked against (ToolsFromProto).
  Eigen::Vector3d tool_lower_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d tool_upper_ = Eigen::Vector3d::Zero();
  std::uint64_t last_stiffness_version_ = 0;

  // Solve-task-owned (between PendingPoseSlot::BeginRun and EndRun).
  std::optional<FrameSolver> solver_;        // emplaced by HandleStart
  std::atomic<bool> splits_batches_{false};  // SplitsItsBatches: set once, before any solve
  std::optional<WorkerPoolParallelRunner> parallel_runner_;  // for a mesh with a parallel plan
  PoseInput solving_;
  std::shared_ptr<const MaterialFactorization> solve_factorization_;
  FrameStamp solve_stamp_;
  v1::DeformFrame* solve_frame_ = nullptr;

  // The current factorization as the worker pool's batch key (BatchKey), written under mutex_.
  std::atomic<const void*> batch_key_{nullptr};

  Mutex mutex_;
  PendingPoseSlot poses_ DEFORM_GUARDED_BY(mutex_);
  StiffnessSwitch stiffness_ DEFORM_GUARDED_BY(mutex_);
  DeformOutbox outbox_ DEFORM_GUARDED_BY(mutex_);
  StreamWritePump<v1::DeformResponse> pump_ DEFORM_GUARDED_BY(mutex_){
      this, transport_, FinishRule::kErrorOverridesGraceful};
  // The message being written (DeformOutbox keeps it untouched until the next TakeNextWrite).
  const v1::DeformResponse* in_flight_ DEFORM_GUARDED_BY(mutex_) = nullptr;
  std::uint64_t frames_written_ DEFORM_GUARDED_BY(mutex_) = 0;
  // Written frames whose constraints left skin inside a bone (the first is logged).
  std::uint64_t frames_unresolved_ DEFORM_GUARDED_BY(mutex_) = 0;
  // The stream's memory beyond its mesh in the budgets: its buffers (buffer_bytes_, set by
  // HandleStart before they are allocated) and its own factorizations (HoldFactorizationsLocked).
  Admission::MemoryHold memory_ DEFORM_GUARDED_BY(mutex_);
  std::size_t buffer_bytes_ DEFORM_GUARDED_BY(mutex_) = 0;
  std::uint64_t poses_rejected_ DEFORM_GUARDED_BY(mutex_) = 0;
  bool reading_paused_ DEFORM_GUARDED_BY(mutex_) = false;
  bool revoked_ DEFORM_GUARDED_BY(mutex_) = false;  // its token was revoked or changed
  // The call was cancelled: by the client, or by its connection ending (a keepalive ping left
  // unanswered), which may come after the failed read has finished the stream OK.
  bool cancelled_ DEFORM_GUARDED_BY(mutex_) = false;
};

void DeformStreamReactor::OnReadDone(bool ok) {
  if (!ok) {
    // The client half-closed (or the call ended): finish once everything pending is written.
    MutexLock lock(&mutex_);
    pump_.RequestFinish(grpc::Status::OK);
    pump_.Pump();
    return;
  }
  switch (request_.action_case()) {
    case v1::DeformRequest::kStart:
      HandleStart();
      return;
    case v1::DeformRequest::kPose:
      HandlePose();
      return;
    case v1::DeformRequest::kStiffness:
      HandleStiffness();
      return;
    case v1::DeformRequest::ACTION_NOT_SET:
      break;
  }
  Fail(grpc::StatusCode::INVALID_ARGUMENT, "empty DeformRequest (no start, pose or stiffness)");
}

void DeformStreamReactor::Fail(grpc::StatusCode code, const std::string& message) {
  MutexLock lock(&mutex_);
  FailLocked(code, message);
}

void DeformStreamReactor::FailLocked(grpc::StatusCode code, const std::string& message) {
  spdlog::warn("{} ending: {}", log_context_, EscapeControlBytes(BoundStatusMessage(message)));
  pump_.RequestFinish(grpc::Status(code, BoundStatusMessage(message)));
  pump_.Pump();
}

void DeformStreamReactor::Fail(const Status& status) {
  MutexLock lock(&mutex_);
  FailLocked(status);
}

void DeformStreamReactor::FailLocked(const Status& status) {
  const grpc::Status mapped = ToGrpcStatus(status);
  spdlog::warn("{} ending: {}", log_context_, EscapeControlBytes(mapped.error_message()));
  pump_.RequestFinish(mapped);
  pump_.Pump();
}

void DeformStreamReactor::HandleStart() {
  if (model_ != nullptr) {
    Fail(grpc::StatusCode::INVALID_ARGUMENT, "`start` sent twice on one stream");
    return;
  }
  const std::string& mesh_id = request_.start().mesh_id();
  const Status id_length = CheckLength(mesh_id, kMaxMeshIdBytes, "start.mesh_id");
  if (!id_length.ok()) {
    Fail(id_length);
    return;
  }
  auto entry = context_->FindMesh(mesh_id, caller_);
  if (!entry.ok()) {
    Audit(caller_.tenant, "deform", mesh_id, entry.status().ToString());
    Fail(entry.status());
    return;
  }
  const Status attached = context_->registry().AttachStream(**entry);  // unloaded since: NOT_FOUND
  if (!attached.ok()) {
    Audit(caller_.tenant, "deform", mesh_id, attached.ToString());
    Fail(attached);
    return;
  }
  entry_ = std::move(*entry);  // attached: DetachStream in OnDone
  const Status quota = context_->admission().AcquireStream(caller_.tenant);
  Audit(caller_.tenant, "deform", mesh_id, quota.ok() ? "OK" : quota.ToString());
  if (!quota.ok()) {
    Fail(quota);
    return;
  }
  counted_ = true;
  if (!context_->streams().Add(this)) {
    Fail(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
    return;
  }
  registered_ = true;
  // After Add: a reload that swapped the tokens before it is seen here, one after it revokes us.
  if (!context_->auth().StillValid(caller_)) {
    Fail(grpc::StatusCode::UNAUTHENTICATED, "unknown or revoked bearer token");
    return;
  }
  model_ = entry_->model.get();
  tool_lower_ = model_->mesh().vertices.colwise().minCoeff().transpose();
  tool_upper_ = model_->mesh().vertices.colwise().maxCoeff().transpose();
  log_context_ += " mesh=" + entry_->id;
  auto encoder = MakeFrameEncoder(request_.start(), *entry_);
  if (!encoder.ok()) {
    Fail(encoder.status());
    return;
  }
  const std::size_t encoded_bytes = *encoder ? (*encoder)->max_encoded_bytes() : 0;
  const int transform_floats = codec::kFloatsPerBoneTransform * model_->skeleton().num_bones();
  const SkinConstraints* constraints = entry_->constraints.constraints.get();
  const std::size_t bone_surface_bytes = BoneSurfaceTransformBytes(entry_->bones());
  const std::size_t constraint_bytes =
      constraints != nullptr ? FrameSolver::ConstraintBytes(*constraints) : 0;
  std::size_t held_bytes = 0;
  {
    // The buffers are counted in the memory budgets before they are allocated: the solve's
    // scratch, the constraints' scratch, the frames (FrameSlots: three) and a compact encoder's
    // records and output.
    const auto vertices = static_cast<std::size_t>(entry_->client_vertex_count());
    const std::size_t frame_bytes =
        (encoded_bytes > 0 ? encoded_bytes + sizeof(float) * transform_floats
                           : vertices * 3 * sizeof(float)) +
        bone_surface_bytes;
    MutexLock lock(&mutex_);
    buffer_bytes_ = model_->ScratchBytes() + 3 * frame_bytes + constraint_bytes +
                    LatestFrame::Bytes(model_->mesh().num_vertices()) +
                    (encoded_bytes > 0 ? encoded_bytes + vertices * 8 : 0) +
                    (entry_->solve.parallel_plan != nullptr
                         ? FrameSolver::ParallelWorkBytes(*model_, *entry_->solve.parallel_plan)
                         : 0);
    memory_ = context_->admission().HoldMemory(caller_.tenant);
    held_bytes = buffer_bytes_;
    const Status held = memory_.Resize(buffer_bytes_, "a Deform stream's buffers");
    if (!held.ok()) {
      FailLocked(held);
      return;
    }
  }
  latest_ =
      std::make_shared<LatestFrame>(caller_.tenant, entry_->id, model_->mesh().num_vertices());
  context_->latest_frames().Add(stream_id_, latest_);
  // Everything a solve needs, sized once; frames in the client's vertex order.
  solver_.emplace(*model_, entry_->file_metadata.file_vertex_to_mesh, std::move(*encoder));
  if (entry_->solve.parallel_plan != nullptr) {
    parallel_runner_.emplace(&context_->pool());
    solver_->EnableParallel(entry_->solve.parallel_plan.get(), &*parallel_runner_,
                            &context_->registry().open_streams());
    splits_batches_.store(true, std::memory_order_relaxed);
  }
  if (constraints != nullptr) solver_->EnableConstraints(constraints);
  spdlog::info("{} opened: buffers of about {} KiB ({} KiB for the constraints)", log_context_,
               held_bytes >> 10, constraint_bytes >> 10);

  MutexLock lock(&mutex_);
  stiffness_.Reset(model_->default_factorization());
  UpdateBatchKeyLocked();
  outbox_.AllocateFrames(entry_->client_vertex_count(), encoded_bytes, transform_floats,
                         bone_surface_bytes, constraints != nullptr && constraints->active());
  if (!pump_.finish_requested()) StartRead(&request_);
}

Status DeformStreamReactor::StagedTools() {
  staging_.tools.count = 0;
  if (request_.pose().tools_size() == 0) return Status::Ok();
  const SkinConstraints* constraints = entry_->constraints.constraints.get();
  if (constraints == nullptr || !constraints->takes_tools()) {
    return Status::InvalidArgument("this mesh's constraints take no tools");
  }
  return ToolsFromProto(request_.pose(), tool_lower_, tool_upper_, &staging_.tools);
}

void DeformStreamReactor::HandlePose() {
  if (model_ == nullptr) {
    Fail(grpc::StatusCode::INVALID_ARGUMENT, "the first DeformRequest must be `start`");
    return;
  }
  Status converted = PoseInputFromProto(request_.pose(), model_->skeleton(), &staging_);
  if (converted.ok()) converted = StagedTools();
  staging_.arrival = Clock::now();
  bool post = false;
  {
    MutexLock lock(&mutex_);
    if (pump_.finish_requested()) return;
    if (!converted.ok()) {
      ++poses_rejected_;
      if (!outbox_.notice_backlog_full()) {
        const std::uint64_t sequence = request_.pose().sequence();
        outbox_.AddNotice(v1::Notice::KIND_POSE_REJECTED, sequence, stiffness_.current_version(),
                          "pose " + std::to_string(sequence) + ": " + converted.message());
        pump_.Pump();
      }
    } else {
      post = poses_.Offer(&staging_);
    }
    ReadNextLocked();
  }
  if (post) context_->pool().PostUrgent(SharedFromThis());
}

void DeformStreamReactor::HandleStiffness() {
  if (model_ == nullptr) {
    Fail(grpc::StatusCode::INVALID_ARGUMENT, "the first DeformRequest must be `start`");
    return;
  }
  const std::uint64_t version = ++last_stiffness_version_;
  auto stiffness =
      StiffnessFromProto(request_.stiffness(), *model_, entry_->file_metadata.file_vertex_to_mesh);
  MutexLock lock(&mutex_);
  if (pump_.finish_requested()) return;
  if (!stiffness.ok()) {
    RejectStiffnessLocked(version, stiffness.status().message());
  } else if (stiffness_.refactor_running()) {
    if (const auto superseded = stiffness_.Wait({std::move(*stiffness), version})) {
      SupersedeStiffnessLocked(*superseded, version, "before its refactorization started");
    }
  } else {
    StartRefactorLocked({std::move(*stiffness), version});
  }
  pump_.Pump();
  ReadNextLocked();
}

void DeformStreamReactor::RejectStiffnessLocked(std::uint64_t version, const std::string& why) {
  spdlog::info("{} stiffness version {} rejected: {}", log_context_, version,
               EscapeControlBytes(BoundStatusMessage(why)));
  outbox_.AddNotice(v1::Notice::KIND_STIFFNESS_REJECTED, 0, version,
                    "stiffness version " + std::to_string(version) + ": " + why);
}

void DeformStreamReactor::SupersedeStiffnessLocked(std::uint64_t superseded, std::uint64_t by,
                                                   const char* when) {
  outbox_.AddNotice(v1::Notice::KIND_STIFFNESS_REJECTED, 0, superseded,
                    "stiffness version " + std::to_string(superseded) + " superseded by version " +
                        std::to_string(by) + " " + when);
}

void DeformStreamReactor::ReadNextLocked() {
  if (outbox_.notice_backlog_full()) {
    reading_paused_ = true;
    return;
  }
  StartRead(&request_);
}

Status DeformStreamReactor::HoldFactorizationsLocked(int running, const std::string& what) {
  const bool own_current = stiffness_.current() != model_->default_factorization();
  const std::size_t count =
      (own_current ? 1 : 0) + (stiffness_.has_next() ? 1 : 0) + static_cast<std::size_t>(running);
  return memory_.Resize(buffer_bytes_ + count * model_->FactorizationBytes(), what);
}

void DeformStreamReactor::StartRefactorLocked(StiffnessSwitch::Update update) {
  const Status held = HoldFactorizationsLocked(
      1, "the factorization of stiffness version " + std::to_string(update.version));
  if (!held.ok()) {
    RejectStiffnessLocked(update.version, held.message());
    return;
  }
  stiffness_.RefactorStarted();
  context_->pool().PostBackground(
      [self = SharedFromThis(), update = std::move(update)] { self->Refactor(update); });
}

void DeformStreamReactor::Refactor(const StiffnessSwitch::Update& update) {
  bool skip;
  {
    MutexLock lock(&mutex_);
    skip = pump_.failing();
  }
  const auto started = std::chrono::steady_clock::now();
  StatusOr<std::shared_ptr<const MaterialFactorization>> result =
      skip ? StatusOr<std::shared_ptr<const MaterialFactorization>>(
                 Status::FailedPrecondition("stream ending"))
           : model_->Factorize(update.stiffness);
  if (!skip) {
    context_->metrics().RefactorizationFinished(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  }
  const std::uint64_t version = update.version;
  MutexLock lock(&mutex_);
  stiffness_.RefactorEnded();
  if (!pump_.failing()) {
    if (result.ok()) {
      if (const auto superseded = stiffness_.SetNext(std::move(*result), version)) {
        SupersedeStiffnessLocked(*superseded, version, "before it was applied");
      }
      // Between two solves now: switch at once. During a solve: the solve task switches after it.
      if (!poses_.running()) ApplyNextFactorizationLocked();
    } else {
      RejectStiffnessLocked(version, result.status().message());
    }
    if (auto waiting = stiffness_.TakeWaiting()) StartRefactorLocked(std::move(*waiting));
  }
  if (!stiffness_.refactor_running()) (void)HoldFactorizationsLocked(0, "");  // shrinks only
  pump_.Pump();
}

void DeformStreamReactor::UpdateBatchKeyLocked() {
  const MaterialFactorization* current = stiffness_.current().get();
  batch_key_.store(current->linear_response() != nullptr ? nullptr : current,
                   std::memory_order_relaxed);
}

void DeformStreamReactor::ApplyNextFactorizationLocked() {
  const std::uint64_t version = stiffness_.ApplyNext();
  UpdateBatchKeyLocked();
  const double factor_ms = stiffness_.current()->factor_seconds() * 1e3;
  spdlog::info("{} stiffness version {} applied (factorization {:.2f} ms)", log_context_, version,
               factor_ms);
  outbox_.AddNotice(v1::Notice::KIND_STIFFNESS_APPLIED, 0, version,
                    "stiffness version " + std::to_string(version) + " applied", factor_ms);
  // The previous factorization of the stream's own (if any) is released with this switch.
  (void)HoldFactorizationsLocked(stiffness_.refactor_running() ? 1 : 0, "");  // shrinks only
}

void DeformStreamReactor::RunUrgent() { RunUrgentBatch(nullptr, 0); }

void DeformStreamReactor::RunUrgentBatch(FrameTask* const* others, int count) {
  // The members: this stream and the others (all DeformStreamReactors: only they have keys).
  std::array<DeformStreamReactor*, WorkerPool::kMaxBatch> members;
  int size = 0;
  members[size++] = this;
  for (int i = 0; i < count && size < WorkerPool::kMaxBatch; ++i) {
    members[size++] = static_cast<DeformStreamReactor*>(others[i]);
  }
  // Each member's run begins; those with a pose that converts get solved.
  std::array<DeformStreamReactor*, WorkerPool::kMaxBatch> solving;
  int to_solve = 0;
  for (int i = 0; i < size; ++i) {
    DeformStreamReactor* member = members[i];
    if (!member->BeginSolveRun()) {
      member->EndSolveRun(false);
    } else if (const Status prepared = member->solver_->Prepare(member->solving_); !prepared.ok()) {
      member->RejectSolvingPose(prepared);
      member->EndSolveRun(false);
    } else {
      solving[to_solve++] = member;
    }
  }
  // Grouped by factorization (a member's may have changed since the pool read its key); each group
  // in one pass, its frames then finished and published one by one.
  std::array<FrameSolver*, WorkerPool::kMaxBatch> solvers;
  std::array<DeformStreamReactor*, WorkerPool::kMaxBatch> group;
  while (to_solve > 0) {
    const MaterialFactorization* factorization = solving[0]->solve_factorization_.get();
    int in_group = 0;
    int rest = 0;
    for (int i = 0; i < to_solve; ++i) {
      if (solving[i]->solve_factorization_.get() == factorization) {
        group[in_group] = solving[i];
        solvers[in_group++] = &*solving[i]->solver_;
      } else {
        solving[rest++] = solving[i];
      }
    }
    to_solve = rest;
    const FrameSolver::Deformed deformed = FrameSolver::DeformPrepared(
        *factorization, solvers.data(), in_group, group[0]->entry_->solve.batch_scratches.get());
    for (int i = 0; i < in_group; ++i) {
      DeformStreamReactor* member = group[i];
      member->solver_->Finish(member->solving_, deformed, member->solve_stamp_,
                              member->solve_frame_);
      member->latest_->Publish(member->solver_->solved_positions(), member->solving_.sequence);
      member->EndSolveRun(true);
    }
  }
}

bool DeformStreamReactor::BeginSolveRun() {
  MutexLock lock(&mutex_);
  poses_.BeginRun();
  if (pump_.failing() || revoked_) return false;
  const std::optional<std::uint64_t> skipped = poses_.Take(&solving_);
  if (!skipped.has_value()) return false;
  // The factorization cannot change until EndRun(): ApplyNext waits for the end of the run.
  solve_factorization_ = stiffness_.current();
  solve_stamp_.stiffness_version = stiffness_.current_version();
  solve_stamp_.skipped_poses = *skipped;
  solve_stamp_.mesh_unloaded = entry_->unloaded.load(std::memory_order_relaxed);
  solve_frame_ = outbox_.working_frame()->mutable_frame();
  solve_frame_->set_stream_id(stream_id_);
  return true;
}

void DeformStreamReactor::RejectSolvingPose(const Status& status) {
  MutexLock lock(&mutex_);
  outbox_.AddNotice(v1::Notice::KIND_POSE_REJECTED, solving_.sequence, stiffness_.current_version(),
                    "pose " + std::to_string(solving_.sequence) + ": " + status.message());
}

void DeformStreamReactor::EndSolveRun(bool produced) {
  MutexLock lock(&mutex_);
  if (produced && !pump_.failing()) outbox_.PublishFrame();
  if (stiffness_.has_next() && !pump_.failing()) ApplyNextFactorizationLocked();
  const bool post = poses_.EndRun(/*may_continue=*/!pump_.failing());
  pump_.Pump();
  lock.Unlock();
  if (post) context_->pool().PostUrgent(SharedFromThis());
}

const v1::DeformResponse* DeformStreamReactor::TakeNextWrite() {
  mutex_.AssertHeld();
  in_flight_ = outbox_.TakeNextWrite();
  return in_flight_;
}

void DeformStreamReactor::WriteCompleted(bool ok) {
  mutex_.AssertHeld();
  if (ok && revoked_ && in_flight_ != nullptr && in_flight_->has_notice() &&
      in_flight_->notice().kind() == v1::Notice::KIND_CREDENTIALS_REVOKED) {
    FinishRevokedLocked();  // the pump finishes right after this hook
    return;
  }
  if (ok && in_flight_ != nullptr) CountWritten(*in_flight_, &context_->metrics());
  if (ok && outbox_.frame_in_flight()) {
    ++frames_written_;
    const v1::DeformFrame& frame =
        in_flight_ != nullptr ? in_flight_->frame() : v1::DeformFrame::default_instance();
    if (frame.constraints().unresolved() && frames_unresolved_++ == 0) {
      spdlog::warn("{} frame of pose {} left {} skin vertices inside a bone (deepest {:g})",
                   log_context_, frame.sequence(), frame.constraints().penetrating_after(),
                   frame.constraints().max_depth_after());
    }
  }
  if (ok && reading_paused_ && outbox_.notice_backlog_drained() && !pump_.finish_requested()) {
    reading_paused_ = false;
    StartRead(&request_);
  }
}

bool DeformStreamReactor::ReadyToFinish() {
  mutex_.AssertHeld();
  return poses_.idle() && !poses_.has_pending() && !stiffness_.busy() && outbox_.empty();
}

void DeformStreamReactor::OnWriteDone(bool ok) {
  MutexLock lock(&mutex_);
  pump_.OnWriteDone(ok);
}

void DeformStreamReactor::OnCancel() {
  MutexLock lock(&mutex_);
  cancelled_ = true;
  pump_.RequestFinish(grpc::Status(grpc::StatusCode::CANCELLED, "cancelled by the client"));
  pump_.Pump();
}

void DeformStreamReactor::Drain() {
  MutexLock lock(&mutex_);
  pump_.RequestFinish(grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down"));
  pump_.Pump();
}

void DeformStreamReactor::Revoke() {
  MutexLock lock(&mutex_);
  if (revoked_ || pump_.finish_requested()) return;
  revoked_ = true;
  spdlog::warn("{} ending: its token was revoked or changed (token file reloaded)", log_context_);
  Audit(caller_.tenant, "deform", entry_ != nullptr ? entry_->id : "", "UNAUTHENTICATED: revoked");
  // The notice first; the finish when it is written (WriteCompleted), or now if it was dropped.
  if (!outbox_.AddNotice(v1::Notice::KIND_CREDENTIALS_REVOKED, 0, 0,
                         "the stream's token was revoked or changed; the stream ends "
                         "UNAUTHENTICATED")) {
    FinishRevokedLocked();
  }
  pump_.Pump();
}

void DeformStreamReactor::FinishRevokedLocked() {
  pump_.RequestFinish(
      grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "the stream's token was revoked or changed"));
}

void DeformStreamReactor::OnDone() {
  if (registered_) context_->streams().Remove(this);
  if (latest_ != nullptr) context_->latest_frames().Remove(stream_id_);
  if (counted_) context_->admission().ReleaseStream(caller_.tenant);
  if (entry_ != nullptr) context_->registry().DetachStream(*entry_);
  {
    MutexLock lock(&mutex_);
    const grpc::Status& status = pump_.finish_status();
    // A read that fails because the connection died finishes OK; the cancel that follows says
    // what happened.
    const std::string outcome =
        !status.ok() ? EscapeControlBytes(status.error_message())
        : cancelled_ ? std::string("cancelled: the client or its connection went away")
                     : std::string("OK");
    spdlog::info(
        "{} closed ({}): {} frames written ({} unresolved), {} poses rejected, {} notices dropped",
        log_context_, outcome, frames_written_, frames_unresolved_, poses_rejected_,
        outbox_.notices_dropped());
  }
  ReleaseTransportReference();  // last: may free the reactor
}

}  // namespace

StreamHandler* NewDeformStream(ServiceContext* context, Identity caller,
                               DeformTransport* transport) {
  return DeformStreamReactor::Create(context, std::move(caller), transport);
}

}  // namespace deform::service
