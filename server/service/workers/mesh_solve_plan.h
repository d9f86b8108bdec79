// How a mesh's frames are solved on the worker pool: its batch scratches (batched solves of
// several streams' frames) and its parallel plan (a lone frame or batch split over the workers).
// Made once when the mesh is loaded, before it is registered, and counted in its memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "core/model/deformation_model.h"
#include "service/workers/batch_scratch_pool.h"

namespace deform::service {

// How meshes are prepared for the workers: `slots` batch scratches of `max_frames` frames each
// (one per worker; none when max_frames < 2), a parallel solve plan of `slots` parts for a mesh
// whose factor holds at least parallel_min_factor_bytes (slots >= 2), and the loader's
// ModelOptions::float32_factor_min_bytes (negative: every factor in double).
struct SolveSettings {
  int slots = 0;
  int max_frames = 1;
  std::size_t parallel_min_factor_bytes = std::size_t{8} << 20;
  std::int64_t float32_factor_min_bytes = -1;
};

struct MeshSolvePlan {
  // The buffers of batched solves of the mesh's frames, with room for the parallel plan's batches
  // when there is one; null when its frames are solved one by one (batching off, or a linear
  // response: nothing to share).
  std::unique_ptr<BatchScratchPool> batch_scratches;
  // The split of the mesh's solve over the workers (one part each) for a lone frame or a batch;
  // null when the mesh is too small for it to pay (SolveSettings::parallel_min_factor_bytes) or
  // there is one worker.
  std::unique_ptr<const ParallelSolvePlan> parallel_plan;
  // What the two hold (the batch scratches' buffers).
  std::size_t bytes = 0;
};

// The plan for `model` under `settings`. Allocates the batch scratches.
MeshSolvePlan PlanMeshSolve(const DeformationModel& model, const SolveSettings& settings);

}  // namespace deform::service
