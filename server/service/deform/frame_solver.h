// One Deform stream's solves: a pose in, a frame out, on the stream's own buffers.
//
// Owns the per-stream buffers a solve needs (the core Pose, the DeformScratch), sized once for the
// model, so a solve allocates nothing. Fills a DeformFrame in place: positions as packed
// little-endian float32, the pose's sequence and timestamp, the stamp (stiffness version, skipped
// poses, mesh_unloaded), the clamped angles and the timings (queue time from the pose's arrival);
// with constraints (EnableConstraints), the frame is constrained after its solve, on whichever
// path solved it, and carries its bone surfaces' transforms and its constraint report.
//
// A solve is Prepare (the pose), the deformation (alone, or batched with other streams' solvers on
// the same factorization: DeformPrepared), then Finish (the frame); Solve does all three alone.
//
// Thread safety: one solve at a time (the stream's solve task owns the solver); no lock is taken
// or needed. The model must outlive the solver.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>

#include "core/base/status.h"
#include "core/codec/frame_codec.h"
#include "core/constraints/skin_constraints.h"
#include "core/geometry/pose.h"
#include "core/model/deformation_model.h"
#include "deform/v1/deform.pb.h"
#include "service/deform/pose_input.h"
#include "service/workers/batch_scratch_pool.h"

namespace deform::service {

// What a frame carries besides the solve's own results.
struct FrameStamp {
  std::uint64_t stiffness_version = 0;
  std::uint64_t skipped_poses = 0;
  bool mesh_unloaded = false;
};

class FrameSolver {
 public:
  // `client_order`: per client vertex (the file's order) its solved vertex, or empty for the
  // solved order itself (MeshFileMetadata); it must outlive the solver. `encoder`: the stream's
  // compact encoding (frame_encoding.h), or null for float32 positions.
  FrameSolver(const DeformationModel& model, const std::vector<int>& client_order,
              std::unique_ptr<codec::FrameEncoder> encoder = nullptr);
  // Frames in the solved order.
  explicit FrameSolver(const DeformationModel& model);

  // Lets this solver's frames run on several threads: `plan` (of the model's factor analysis) and
  // `runner`. A batch led by this solver is always split (as DeformBatchParallel splits it, with
  // a batch scratch made for the plan): the pool runs one batch of such a mesh at a time, so the
  // other workers are free unless other meshes' work holds them, and one that frees up during
  // the batch joins it (WorkerPoolParallelRunner). A lone frame is split (as DeformParallel splits
  // it) while fewer streams than the plan has parts (one per worker) are open on the service
  // (`open_streams`, MeshRegistry::open_streams()) or, with more, while the runner has an idle
  // worker (ParallelRunner::IdleHelpers): a split solve costs the workers more time in all than a
  // whole one (docs/performance.md, "Parallel solve"), which pays on a worker that is idle but not
  // on one that has other frames to solve. All three must outlive the solver. Allocates the
  // parallel solve's work: ParallelWorkBytes.
  void EnableParallel(const ParallelSolvePlan* plan, ParallelRunner* runner,
                      const std::atomic<int>* open_streams);
  static std::size_t ParallelWorkBytes(const DeformationModel& model,
                                       const ParallelSolvePlan& plan);

  // Constrains every frame with `constraints` (made for the model; must outlive the solver):
  // Finish applies them to the solution before encoding it (SkinConstraints::Apply, on the
  // factorization that solved it), and fills the frame's bone_transforms and constraints.
  // A frame's tools (PoseInput::tools, checked by ToolsFromProto) go into the same Apply; a
  // frame with tools is constrained even when the constraints hold nothing else (active()).
  // Allocates the constraints' scratch: ConstraintBytes.
  void EnableConstraints(const SkinConstraints* constraints);
  static std::size_t ConstraintBytes(const SkinConstraints& constraints) {
    return constraints.ScratchBytes();
  }

  // Solves `input` with `factorization` (one of the model's) into `frame`: its positions, or with
  // an encoder its `encoded` positions. Sized by FrameSlots::Allocate, a frame allocates nothing;
  // otherwise it is resized (allocating).
  // INVALID_ARGUMENT naming the problem when the pose cannot be built; `frame` is then untouched.
  Status Solve(const PoseInput& input, const MaterialFactorization& factorization,
               const FrameStamp& stamp, v1::DeformFrame* frame);

  // Solve's first step: builds the pose of `input` (INVALID_ARGUMENT as Solve).
  Status Prepare(const PoseInput& input);
  // Deforms the prepared poses of `solvers` (distinct, all of one model, prepared) with
  // `factorization`: together in passes of up to scratches->max_frames() over the factor when
  // `scratches` lends a batch scratch and count > 1, a lone frame or a batch on several threads
  // when the first solver has EnableParallel and splits now, else one by one. No allocation.
  struct Deformed {
    std::chrono::steady_clock::time_point start;           // when the deformation began
    std::chrono::steady_clock::time_point end;             // when it ended
    const MaterialFactorization* factorization = nullptr;  // the one that solved it
    DeformTimings timings;                                 // all of the solvers' together
    int batch_frames = 1;                                  // the largest pass's frames
    int solve_parts = 1;                                   // a lone frame split for several threads
  };
  static Deformed DeformPrepared(const MaterialFactorization& factorization,
                                 FrameSolver* const* solvers, int count,
                                 const BatchScratchPool* scratches);
  // Solve's last step, after DeformPrepared: the frame of `input` from this solver's solution.
  // Its timings: queue_ms up to `deformed.start`, rhs_ms and solve_ms the deformation's (a
  // batch's, for each of its frames), constraint_ms this frame's constraints, encode_ms from the
  // deformation's end to this frame's encoding's end without its constraint_ms (a batch
  // constrains and encodes its frames one after the other).
  void Finish(const PoseInput& input, const Deformed& deformed, const FrameStamp& stamp,
              v1::DeformFrame* frame);
  // The last finished frame's positions in the solved order, constraints applied: row i at
  // [3 i], the model's num_vertices rows. Valid until the next solve.
  const double* solved_positions() const { return scratch_.solution.data(); }

 private:
  const DeformationModel& model_;
  const std::vector<int>& client_order_;
  void Encode(v1::DeformFrame* frame);
  // The constraints applied to the solution, their report and the bone transforms in `frame`;
  // their milliseconds.
  double Constrain(const MaterialFactorization& factorization, const ToolSet& tools,
                   v1::DeformFrame* frame);
  // Whether this solver's frame (`frames` 1), or a batch of `frames` it leads, is split now
  // (EnableParallel).
  bool SplitsNow(int frames) const;
  // DeformPrepared's work, without its start and end times.
  static void DeformTogether(const MaterialFactorization& factorization,
                             FrameSolver* const* solvers, int count,
                             const BatchScratchPool* scratches, Deformed* deformed);

  Pose pose_;
  int clamped_ = 0;  // angles clamped by the last Prepare
  DeformScratch scratch_;
  std::unique_ptr<codec::FrameEncoder> encoder_;
  std::vector<float> bone_transforms_;  // 12 per bone, for predicted frames
  const ParallelSolvePlan* parallel_plan_ = nullptr;
  ParallelRunner* parallel_runner_ = nullptr;
  const std::atomic<int>* open_streams_ = nullptr;
  std::vector<double> parallel_work_;
  const SkinConstraints* constraints_ = nullptr;
  ConstraintScratch constraint_scratch_;
};

}  // namespace deform::service
