#include "service/deform/frame_solver.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cstddef>
#include <string>
#include <utility>

#include "service/messages/frame_encoding.h"
#include "service/messages/proto_conversion.h"

namespace deform::service {
namespace {

using Clock = std::chrono::steady_clock;

double Milliseconds(Clock::duration duration) {
  return std::chrono::duration<double, std::milli>(duration).count();
}

const std::vector<int> kSolvedOrder;

}  // namespace

FrameSolver::FrameSolver(const DeformationModel& model) : FrameSolver(model, kSolvedOrder) {}

FrameSolver::FrameSolver(const DeformationModel& model, const std::vector<int>& client_order,
                         std::unique_ptr<codec::FrameEncoder> encoder)
    : model_(model),
      client_order_(client_order),
      pose_(Pose::Rest(model.skeleton())),
      scratch_(model.MakeScratch()),
      encoder_(std::move(encoder)),
      bone_transforms_(static_cast<std::size_t>(codec::kFloatsPerBoneTransform) *
                       model.skeleton().num_bones()) {}

void FrameSolver::EnableConstraints(const SkinConstraints* constraints) {
  constraints_ = constraints;
  constraint_scratch_ = constraints->MakeScratch();
}

double FrameSolver::Constrain(const MaterialFactorization& factorization, const ToolSet& tools,
                              v1::DeformFrame* frame) {
  const auto start = Clock::now();
  ConstraintReport report;
  const bool applied = constraints_->Apply(factorization, &scratch_, &constraint_scratch_, &report,
                                           tools.empty() ? nullptr : &tools);
  assert(applied &&
         "the constraints, the factorization and the scratch are of one model, and "
         "the stream takes tools only when the constraints do");
  (void)applied;
  v1::FrameConstraints* out = frame->mutable_constraints();
  out->set_penetrating_before(static_cast<std::uint32_t>(report.before.vertices));
  out->set_penetrating_after(static_cast<std::uint32_t>(report.after.vertices));
  out->set_max_depth_after(report.after.max_depth);
  out->set_unresolved(report.unresolved);
  out->set_contacts(static_cast<std::uint32_t>(report.contacts));
  out->set_volume_change(report.volume_change_after);
  out->set_tool_penetrating_before(static_cast<std::uint32_t>(report.tool_before.vertices));
  out->set_tool_penetrating_after(static_cast<std::uint32_t>(report.tool_after.vertices));
  out->set_tool_max_depth_after(report.tool_after.max_depth);
  out->set_tool_contacts(static_cast<std::uint32_t>(report.tool_contacts));
  out->set_tools_unresolved(report.tools_unresolved);
  if (const BoneContacts* bones = constraints_->bones()) {
    std::string* transforms = frame->mutable_bone_transforms();
    transforms->resize(BoneSurfaceTransformBytes(bones));  // no-op when sized by FrameSlots
    EncodeBoneSurfaceTransforms(*bones, model_.skeleton(), scratch_.bone_transforms,
                                transforms->data());
  }
  return Milliseconds(Clock::now() - start);
}

void FrameSolver::EnableParallel(const ParallelSolvePlan* plan, ParallelRunner* runner,
                                 const std::atomic<int>* open_streams) {
  parallel_plan_ = plan;
  parallel_runner_ = runner;
  open_streams_ = open_streams;
  parallel_work_.assign(model_.default_factorization()->factor().WorkSizeParallel(*plan), 0.0);
}

bool FrameSolver::SplitsNow(int frames) const {
  return parallel_plan_ != nullptr &&
         (frames > 1 || open_streams_->load(std::memory_order_relaxed) < parallel_plan_->parts ||
          parallel_runner_->IdleHelpers() > 0);
}

std::size_t FrameSolver::ParallelWorkBytes(const DeformationModel& model,
                                           const ParallelSolvePlan& plan) {
  return sizeof(double) * model.default_factorization()->factor().WorkSizeParallel(plan);
}

void FrameSolver::Encode(v1::DeformFrame* frame) {
  v1::EncodedPositions* encoded = frame->mutable_encoded();
  std::string* data = encoded->mutable_data();
  data->resize(encoder_->max_encoded_bytes());  // within its capacity after FrameSlots::Allocate
  const float* transforms = nullptr;
  if (encoder_->predicted()) {
    BoneTransformsAsFloats(scratch_.bone_transforms, bone_transforms_.data());
    transforms = bone_transforms_.data();
  }
  codec::EncodedFrameHeader header;
  data->resize(encoder_->Encode(scratch_.solution.data(), client_order_, transforms, &header,
                                reinterpret_cast<unsigned char*>(data->data())));
  const bool predicted = header.encoding == codec::FrameEncoding::kPredicted;
  encoded->set_encoding(predicted ? v1::FRAME_ENCODING_PREDICTED : v1::FRAME_ENCODING_QUANTIZED);
  encoded->set_step(header.step);
  encoded->set_max_error(header.max_error);
  encoded->mutable_origin()->Resize(predicted ? 0 : 3, 0.0);
  for (int a = 0; !predicted && a < 3; ++a) encoded->mutable_origin()->Set(a, header.origin[a]);
  auto* floats = encoded->mutable_bone_transforms();
  floats->Resize(predicted ? static_cast<int>(bone_transforms_.size()) : 0, 0.0f);
  if (predicted) std::copy(bone_transforms_.begin(), bone_transforms_.end(), floats->begin());
}

Status FrameSolver::Solve(const PoseInput& input, const MaterialFactorization& factorization,
                          const FrameStamp& stamp, v1::DeformFrame* frame) {
  DEFORM_RETURN_IF_ERROR(Prepare(input));
  FrameSolver* const self = this;
  const Deformed deformed = DeformPrepared(factorization, &self, 1, nullptr);
  Finish(input, deformed, stamp, frame);
  return Status::Ok();
}

Status FrameSolver::Prepare(const PoseInput& input) {
  DEFORM_ASSIGN_OR_RETURN(clamped_, PoseFromInput(model_.skeleton(), input, &pose_));
  return Status::Ok();
}

FrameSolver::Deformed FrameSolver::DeformPrepared(const MaterialFactorization& factorization,
                                                  FrameSolver* const* solvers, int count,
                                                  const BatchScratchPool* scratches) {
  Deformed deformed;
  deformed.factorization = &factorization;
  deformed.start = Clock::now();
  if (count > 0) DeformTogether(factorization, solvers, count, scratches, &deformed);
  deformed.end = Clock::now();
  return deformed;
}

void FrameSolver::DeformTogether(const MaterialFactorization& factorization,
                                 FrameSolver* const* solvers, int count,
                                 const BatchScratchPool* scratches, Deformed* deformed) {
  const DeformationModel& model = solvers[0]->model_;
  const bool split = solvers[0]->SplitsNow(count);
  if (count == 1 && split) {
    FrameSolver& solver = *solvers[0];
    model.DeformParallel(factorization, solver.pose_, &solver.scratch_, *solver.parallel_plan_,
                         solver.parallel_work_.data(), solver.parallel_runner_, &deformed->timings);
    deformed->solve_parts = solver.parallel_plan_->parts;
    return;
  }
  const BatchScratchPool::Lease lease =
      count > 1 && scratches != nullptr ? scratches->TryAcquire() : BatchScratchPool::Lease();
  if (!lease) {
    for (int i = 0; i < count; ++i) {
      DeformTimings one;
      model.Deform(factorization, solvers[i]->pose_, &solvers[i]->scratch_, &one);
      deformed->timings.right_hand_side += one.right_hand_side;
      deformed->timings.solve += one.solve;
    }
    return;
  }
  const int max_frames = lease.get()->max_frames;
  std::array<const Pose*, DeformationModel::kMaxBatchFrames> poses;
  std::array<DeformScratch*, DeformationModel::kMaxBatchFrames> buffers;
  for (int first = 0; first < count; first += max_frames) {
    const int frames = std::min(max_frames, count - first);
    for (int f = 0; f < frames; ++f) {
      poses[f] = &solvers[first + f]->pose_;
      buffers[f] = &solvers[first + f]->scratch_;
    }
    DeformTimings pass;
    if (split) {
      const FrameSolver& leader = *solvers[0];
      model.DeformBatchParallel(factorization, poses.data(), buffers.data(), frames, lease.get(),
                                *leader.parallel_plan_, leader.parallel_runner_, &pass);
      deformed->solve_parts = leader.parallel_plan_->parts;
    } else {
      model.DeformBatch(factorization, poses.data(), buffers.data(), frames, lease.get(), &pass);
    }
    deformed->timings.right_hand_side += pass.right_hand_side;
    deformed->timings.solve += pass.solve;
    deformed->batch_frames = std::max(deformed->batch_frames, frames);
  }
}

void FrameSolver::Finish(const PoseInput& input, const Deformed& deformed, const FrameStamp& stamp,
                         v1::DeformFrame* frame) {
  const std::size_t client_vertices = client_order_.empty()
                                          ? static_cast<std::size_t>(scratch_.num_vertices)
                                          : client_order_.size();
  const bool constrained =
      constraints_ != nullptr && (constraints_->active() || !input.tools.empty());
  const double constraint_ms =
      constrained ? Constrain(*deformed.factorization, input.tools, frame) : 0.0;
  // A mesh whose constraints act only with tools: a frame without them reports zeros (its slot
  // may hold an earlier tool frame's report; cleared, not freed, so no frame allocates).
  if (!constrained && frame->has_constraints()) frame->mutable_constraints()->Clear();
  if (encoder_) {
    Encode(frame);
  } else {
    frame->mutable_positions()->resize(client_vertices * 12);  // no-op when sized by FrameSlots
    EncodeInClientOrder(scratch_.solution.data(), scratch_.num_vertices, client_order_,
                        frame->mutable_positions()->data());
  }
  frame->set_sequence(input.sequence);
  frame->set_client_timestamp_ns(input.client_timestamp_ns);
  frame->set_stiffness_version(stamp.stiffness_version);
  frame->set_skipped_poses(stamp.skipped_poses);
  frame->set_clamped_angles(static_cast<std::uint32_t>(clamped_));
  frame->set_mesh_unloaded(stamp.mesh_unloaded);
  v1::FrameTimings* frame_timings = frame->mutable_timings();
  frame_timings->set_queue_ms(Milliseconds(deformed.start - input.arrival));
  frame_timings->set_rhs_ms(deformed.timings.right_hand_side * 1e3);
  frame_timings->set_solve_ms(deformed.timings.solve * 1e3);
  frame_timings->set_constraint_ms(constraint_ms);
  frame_timings->set_encode_ms(
      std::max(0.0, Milliseconds(Clock::now() - deformed.end) - constraint_ms));
  frame_timings->set_batch_frames(static_cast<std::uint32_t>(deformed.batch_frames));
  frame_timings->set_solve_parts(static_cast<std::uint32_t>(deformed.solve_parts));
}

}  // namespace deform::service
