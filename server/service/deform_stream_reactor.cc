#include "service/deform_stream_reactor.h"

#include <spdlog/spdlog.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "core/geometry/pose.h"
#include "core/model/deformation_model.h"
#include "service/pose_input.h"
#include "service/proto_conversion.h"
#include "service/shared_reactor.h"
#include "service/status_mapping.h"

namespace deform::service {
namespace {

using Clock = std::chrono::steady_clock;

// Unwritten notices beyond which new KIND_POSE_REJECTED notices are dropped (a client flooding bad
// poses without reading must not grow the server's memory).
constexpr std::size_t kMaxPendingNotices = 1024;

double Milliseconds(Clock::duration duration) {
  return std::chrono::duration<double, std::milli>(duration).count();
}

class DeformStreamReactor final
    : public grpc::ServerBidiReactor<v1::DeformRequest, v1::DeformResponse>,
      public SharedReactor<DeformStreamReactor>,
      public UrgentTask,
      private Drainable {
 public:
  explicit DeformStreamReactor(ServiceCore* core)
      : core_(core), stream_id_(core->next_stream_id.fetch_add(1)) {
    log_context_ = "stream=" + std::to_string(stream_id_);
    StartRead(&request_);
  }

  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnCancel() override;
  void OnDone() override;

 private:
  enum class TaskState { kIdle, kQueued, kRunning };

  // Reactions' helpers (gRPC threads).
  void HandleStart();
  void HandlePose();
  void HandleStiffness();
  void FailLocked(grpc::StatusCode code, const std::string& message);

  // UrgentTask: one solve on a worker.
  void RunUrgent() override;
  // Drainable.
  void Drain() override;

  // Background refactorisation for stiffness version `version`.
  void Refactor(const Stiffness& stiffness, std::uint64_t version);

  // All *Locked helpers require mutex_.
  // Marks the task queued if idle; true if the caller must post it.
  bool ScheduleLocked();
  void StartRefactorLocked(Stiffness stiffness, std::uint64_t version);
  void AdoptFactorizationLocked();
  void AddNoticeLocked(v1::Notice::Kind kind, std::uint64_t sequence, std::uint64_t version,
                       const std::string& message, double factor_ms = 0);
  void RequestFinishLocked(const grpc::Status& status);
  // Starts the next write, or Finish when due. Never more than one write in flight.
  void PumpLocked();
  bool NothingPendingLocked() const;

  ServiceCore* const core_;
  const std::uint64_t stream_id_;
  std::string log_context_;  // "stream=N mesh=ID", for logs

  // Set by HandleStart before any worker can see the stream; read-only afterwards.
  std::shared_ptr<const MeshEntry> entry_;
  const DeformationModel* model_ = nullptr;
  bool registered_ = false;  // in core_->streams

  // Reader-owned (one read outstanding at a time).
  v1::DeformRequest request_;
  PoseInput staging_;
  std::uint64_t last_stiffness_version_ = 0;

  // Worker-owned while task_state_ == kRunning (and the factorisation: see
  // AdoptFactorizationLocked).
  PoseInput working_;
  Pose pose_;
  DeformScratch scratch_;
  std::shared_ptr<const MaterialFactorization> factorization_;
  std::uint64_t version_ = 0;
  v1::DeformResponse* working_frame_ = nullptr;

  std::mutex mutex_;
  // Everything below is guarded by mutex_.
  bool started_ = false;
  TaskState task_state_ = TaskState::kIdle;
  PoseInput pending_;
  bool has_pending_ = false;
  std::uint64_t skipped_ = 0;  // poses replaced in the pending slot since the last solve

  bool refactor_running_ = false;
  bool has_queued_stiffness_ = false;
  Stiffness queued_stiffness_;
  std::uint64_t queued_version_ = 0;
  std::shared_ptr<const MaterialFactorization> next_factorization_;  // done, not yet switched in
  std::uint64_t next_version_ = 0;
  double next_factor_ms_ = 0;

  std::array<v1::DeformResponse, 3> frames_;  // working, ready, writing (pointers rotate)
  v1::DeformResponse* ready_frame_ = nullptr;
  v1::DeformResponse* writing_frame_ = nullptr;
  bool has_ready_frame_ = false;
  std::deque<v1::DeformResponse> notices_;
  std::size_t notices_before_frame_ = 0;  // notices queued before the ready frame was
  v1::DeformResponse notice_in_flight_;
  bool write_in_flight_ = false;
  bool frame_in_flight_ = false;

  bool finish_requested_ = false;
  bool stopping_ = false;  // finishing with an error: no more solves or writes
  bool finish_called_ = false;
  grpc::Status finish_status_;

  std::uint64_t frames_written_ = 0;
  std::uint64_t poses_rejected_ = 0;
};

void DeformStreamReactor::OnReadDone(bool ok) {
  if (!ok) {
    // The client half-closed (or the call ended): finish once everything pending is written.
    std::lock_guard<std::mutex> lock(mutex_);
    RequestFinishLocked(grpc::Status::OK);
    PumpLocked();
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
  std::lock_guard<std::mutex> lock(mutex_);
  FailLocked(grpc::StatusCode::INVALID_ARGUMENT,
             "empty DeformRequest (no start, pose or stiffness)");
}

void DeformStreamReactor::FailLocked(grpc::StatusCode code, const std::string& message) {
  spdlog::warn("{} ending: {}", log_context_, message);
  RequestFinishLocked(grpc::Status(code, message));
  PumpLocked();
}

void DeformStreamReactor::HandleStart() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (started_) {
      FailLocked(grpc::StatusCode::INVALID_ARGUMENT, "`start` sent twice on one stream");
      return;
    }
  }
  const std::string mesh_id = request_.start().mesh_id();
  auto entry = core_->registry.Find(mesh_id);
  if (!entry.ok()) {
    std::lock_guard<std::mutex> lock(mutex_);
    FailLocked(ToGrpcCode(entry.status().code()), entry.status().message());
    return;
  }
  if (!core_->streams.Add(this)) {
    std::lock_guard<std::mutex> lock(mutex_);
    FailLocked(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
    return;
  }
  registered_ = true;
  entry_ = std::move(*entry);
  entry_->open_streams.fetch_add(1);
  model_ = entry_->model.get();
  log_context_ += " mesh=" + entry_->id;

  // Everything a solve needs, sized once.
  scratch_ = model_->MakeScratch();
  pose_ = Pose::Rest(model_->skeleton());
  factorization_ = model_->default_factorization();
  const std::size_t position_bytes = static_cast<std::size_t>(model_->mesh().num_vertices()) * 12;
  for (v1::DeformResponse& response : frames_) {
    v1::DeformFrame* frame = response.mutable_frame();
    frame->mutable_positions()->resize(position_bytes);
    frame->mutable_timings();
  }
  working_frame_ = &frames_[0];
  spdlog::info("{} opened", log_context_);

  std::lock_guard<std::mutex> lock(mutex_);
  ready_frame_ = &frames_[1];
  writing_frame_ = &frames_[2];
  started_ = true;
  if (!finish_requested_) StartRead(&request_);
}

void DeformStreamReactor::HandlePose() {
  if (model_ == nullptr) {
    std::lock_guard<std::mutex> lock(mutex_);
    FailLocked(grpc::StatusCode::INVALID_ARGUMENT, "the first DeformRequest must be `start`");
    return;
  }
  const Status converted = PoseInputFromProto(request_.pose(), model_->skeleton(), &staging_);
  staging_.arrival = Clock::now();
  bool post = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finish_requested_) return;
    if (!converted.ok()) {
      ++poses_rejected_;
      if (notices_.size() < kMaxPendingNotices) {
        AddNoticeLocked(
            v1::Notice::KIND_POSE_REJECTED, request_.pose().sequence(), version_,
            "pose " + std::to_string(request_.pose().sequence()) + ": " + converted.message());
        PumpLocked();
      }
    } else {
      if (has_pending_) ++skipped_;
      std::swap(staging_, pending_);
      has_pending_ = true;
      post = ScheduleLocked();
    }
    StartRead(&request_);
  }
  if (post) core_->pool.PostUrgent(SharedFromThis());
}

void DeformStreamReactor::HandleStiffness() {
  if (model_ == nullptr) {
    std::lock_guard<std::mutex> lock(mutex_);
    FailLocked(grpc::StatusCode::INVALID_ARGUMENT, "the first DeformRequest must be `start`");
    return;
  }
  const std::uint64_t version = ++last_stiffness_version_;
  auto stiffness = StiffnessFromProto(request_.stiffness(), *model_);
  std::lock_guard<std::mutex> lock(mutex_);
  if (finish_requested_) return;
  if (!stiffness.ok()) {
    spdlog::info("{} stiffness version {} rejected: {}", log_context_, version,
                 stiffness.status().message());
    AddNoticeLocked(
        v1::Notice::KIND_STIFFNESS_REJECTED, 0, version,
        "stiffness version " + std::to_string(version) + ": " + stiffness.status().message());
  } else if (refactor_running_) {
    if (has_queued_stiffness_) {
      AddNoticeLocked(v1::Notice::KIND_STIFFNESS_REJECTED, 0, queued_version_,
                      "stiffness version " + std::to_string(queued_version_) +
                          " superseded by version " + std::to_string(version) +
                          " before its refactorisation started");
    }
    queued_stiffness_ = std::move(*stiffness);
    queued_version_ = version;
    has_queued_stiffness_ = true;
  } else {
    StartRefactorLocked(std::move(*stiffness), version);
  }
  PumpLocked();
  StartRead(&request_);
}

void DeformStreamReactor::StartRefactorLocked(Stiffness stiffness, std::uint64_t version) {
  refactor_running_ = true;
  core_->pool.PostBackground([self = SharedFromThis(), stiffness = std::move(stiffness), version] {
    self->Refactor(stiffness, version);
  });
}

void DeformStreamReactor::Refactor(const Stiffness& stiffness, std::uint64_t version) {
  bool skip;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    skip = stopping_;
  }
  StatusOr<std::shared_ptr<const MaterialFactorization>> result =
      skip ? StatusOr<std::shared_ptr<const MaterialFactorization>>(
                 Status::FailedPrecondition("stream ending"))
           : model_->Factorize(stiffness);
  std::lock_guard<std::mutex> lock(mutex_);
  refactor_running_ = false;
  if (!stopping_) {
    if (result.ok()) {
      if (next_factorization_ != nullptr) {
        AddNoticeLocked(v1::Notice::KIND_STIFFNESS_REJECTED, 0, next_version_,
                        "stiffness version " + std::to_string(next_version_) +
                            " superseded by version " + std::to_string(version) +
                            " before it was applied");
      }
      next_factor_ms_ = (*result)->factor_seconds() * 1e3;
      next_factorization_ = std::move(*result);
      next_version_ = version;
      // Between two solves now: switch at once. During a solve: the worker switches after it.
      if (task_state_ != TaskState::kRunning) AdoptFactorizationLocked();
    } else {
      spdlog::info("{} stiffness version {} rejected: {}", log_context_, version,
                   result.status().message());
      AddNoticeLocked(
          v1::Notice::KIND_STIFFNESS_REJECTED, 0, version,
          "stiffness version " + std::to_string(version) + ": " + result.status().message());
    }
    if (has_queued_stiffness_) {
      has_queued_stiffness_ = false;
      StartRefactorLocked(std::move(queued_stiffness_), queued_version_);
      queued_stiffness_ = Stiffness();
    }
  }
  PumpLocked();
}

void DeformStreamReactor::AdoptFactorizationLocked() {
  factorization_ = std::move(next_factorization_);
  next_factorization_ = nullptr;
  version_ = next_version_;
  spdlog::info("{} stiffness version {} applied (factorisation {:.2f} ms)", log_context_, version_,
               next_factor_ms_);
  AddNoticeLocked(v1::Notice::KIND_STIFFNESS_APPLIED, 0, version_,
                  "stiffness version " + std::to_string(version_) + " applied", next_factor_ms_);
}

bool DeformStreamReactor::ScheduleLocked() {
  if (task_state_ != TaskState::kIdle) return false;
  task_state_ = TaskState::kQueued;
  return true;
}

void DeformStreamReactor::RunUrgent() {
  std::unique_lock<std::mutex> lock(mutex_);
  task_state_ = TaskState::kRunning;
  const bool solve = has_pending_ && !stopping_;
  std::uint64_t skipped = 0;
  if (solve) {
    std::swap(pending_, working_);
    has_pending_ = false;
    skipped = skipped_;
    skipped_ = 0;
  }
  lock.unlock();

  bool produced = false;
  if (solve) {
    const Clock::time_point solve_start = Clock::now();
    const StatusOr<int> clamped = PoseFromInput(model_->skeleton(), working_, &pose_);
    if (clamped.ok()) {
      DeformTimings timings;
      model_->Deform(*factorization_, pose_, &scratch_, &timings);
      const Clock::time_point encode_start = Clock::now();
      v1::DeformFrame* frame = working_frame_->mutable_frame();
      EncodeFloat32(scratch_.solution.data(), static_cast<std::size_t>(scratch_.num_vertices) * 3,
                    frame->mutable_positions()->data());
      frame->set_sequence(working_.sequence);
      frame->set_client_timestamp_ns(working_.client_timestamp_ns);
      frame->set_stiffness_version(version_);
      frame->set_skipped_poses(skipped);
      frame->set_clamped_angles(static_cast<std::uint32_t>(*clamped));
      frame->set_mesh_unloaded(entry_->unloaded.load(std::memory_order_relaxed));
      v1::FrameTimings* frame_timings = frame->mutable_timings();
      frame_timings->set_queue_ms(Milliseconds(solve_start - working_.arrival));
      frame_timings->set_rhs_ms(timings.right_hand_side * 1e3);
      frame_timings->set_solve_ms(timings.solve * 1e3);
      frame_timings->set_encode_ms(Milliseconds(Clock::now() - encode_start));
      produced = true;
    } else {
      lock.lock();
      AddNoticeLocked(
          v1::Notice::KIND_POSE_REJECTED, working_.sequence, version_,
          "pose " + std::to_string(working_.sequence) + ": " + clamped.status().message());
      lock.unlock();
    }
  }

  lock.lock();
  if (produced && !stopping_) {
    if (has_ready_frame_) {
      // The unwritten frame is superseded: its pose and the poses it skipped count as skipped.
      v1::DeformFrame* frame = working_frame_->mutable_frame();
      frame->set_skipped_poses(frame->skipped_poses() + ready_frame_->frame().skipped_poses() + 1);
    }
    std::swap(working_frame_, ready_frame_);
    has_ready_frame_ = true;
    notices_before_frame_ = notices_.size();
  }
  if (next_factorization_ != nullptr && !stopping_) AdoptFactorizationLocked();
  bool post = false;
  if (has_pending_ && !stopping_) {
    task_state_ = TaskState::kQueued;  // back of the queue, for fairness
    post = true;
  } else {
    task_state_ = TaskState::kIdle;
  }
  PumpLocked();
  lock.unlock();
  if (post) core_->pool.PostUrgent(SharedFromThis());
}

void DeformStreamReactor::AddNoticeLocked(v1::Notice::Kind kind, std::uint64_t sequence,
                                          std::uint64_t version, const std::string& message,
                                          double factor_ms) {
  v1::Notice* notice = notices_.emplace_back().mutable_notice();
  notice->set_kind(kind);
  notice->set_sequence(sequence);
  notice->set_stiffness_version(version);
  notice->set_message(message);
  notice->set_factor_ms(factor_ms);
}

void DeformStreamReactor::RequestFinishLocked(const grpc::Status& status) {
  if (stopping_) return;  // an error finish is already on its way
  if (!status.ok()) {
    stopping_ = true;
    finish_status_ = status;
  } else if (finish_requested_) {
    return;
  }
  finish_requested_ = true;
}

bool DeformStreamReactor::NothingPendingLocked() const {
  return task_state_ == TaskState::kIdle && !has_pending_ && !has_ready_frame_ &&
         notices_.empty() && !refactor_running_ && !has_queued_stiffness_;
}

void DeformStreamReactor::PumpLocked() {
  if (finish_called_ || write_in_flight_) return;
  if (stopping_) {
    finish_called_ = true;
    Finish(finish_status_);
    return;
  }
  if (has_ready_frame_ && notices_before_frame_ == 0) {
    std::swap(ready_frame_, writing_frame_);
    has_ready_frame_ = false;
    write_in_flight_ = true;
    frame_in_flight_ = true;
    StartWrite(writing_frame_);
    return;
  }
  if (!notices_.empty()) {
    notice_in_flight_.Swap(&notices_.front());
    notices_.pop_front();
    if (notices_before_frame_ > 0) --notices_before_frame_;
    write_in_flight_ = true;
    frame_in_flight_ = false;
    StartWrite(&notice_in_flight_);
    return;
  }
  if (finish_requested_ && NothingPendingLocked()) {
    finish_called_ = true;
    Finish(grpc::Status::OK);
  }
}

void DeformStreamReactor::OnWriteDone(bool ok) {
  std::lock_guard<std::mutex> lock(mutex_);
  write_in_flight_ = false;
  if (ok && frame_in_flight_) ++frames_written_;
  if (!ok) RequestFinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "write failed"));
  PumpLocked();
}

void DeformStreamReactor::OnCancel() {
  std::lock_guard<std::mutex> lock(mutex_);
  RequestFinishLocked(grpc::Status(grpc::StatusCode::CANCELLED, "cancelled by the client"));
  PumpLocked();
}

void DeformStreamReactor::Drain() {
  std::lock_guard<std::mutex> lock(mutex_);
  RequestFinishLocked(grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down"));
  PumpLocked();
}

void DeformStreamReactor::OnDone() {
  if (registered_) core_->streams.Remove(this);
  if (entry_ != nullptr) entry_->open_streams.fetch_sub(1);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    spdlog::info("{} closed ({}): {} frames written, {} poses rejected", log_context_,
                 finish_status_.ok() ? std::string("OK") : finish_status_.error_message(),
                 frames_written_, poses_rejected_);
  }
  ReleaseTransportReference();  // last: may free the reactor
}

}  // namespace

grpc::ServerBidiReactor<v1::DeformRequest, v1::DeformResponse>* NewDeformStreamReactor(
    ServiceCore* core) {
  return DeformStreamReactor::Create(core);
}

}  // namespace deform::service
