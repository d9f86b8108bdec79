// The batched solve's buffers of one mesh (DeformBatchScratch: the right-hand sides side by side
// and the solve's work), one per worker that may be solving a batch of the mesh's frames at once.
// Made with the mesh's entry and counted in its memory (Bytes), so a batch allocates nothing and
// its memory is in the budgets from the start. A worker leases a scratch for one batch; when none
// is free it solves the batch's frames one by one (never waits).
//
// Thread safety: TryAcquire and a Lease's release may be called from any thread.
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <vector>

#include "core/model/deformation_model.h"

namespace deform::service {

class BatchScratchPool {
 public:
  // `slots` scratches of `max_frames` frames each (DeformationModel::MakeBatchScratch), with room
  // for DeformBatchParallel with `parallel` when it is given.
  BatchScratchPool(const DeformationModel& model, int slots, int max_frames,
                   const ParallelSolvePlan* parallel = nullptr);
  BatchScratchPool(const BatchScratchPool&) = delete;
  BatchScratchPool& operator=(const BatchScratchPool&) = delete;

  // What the constructor allocates.
  static std::size_t Bytes(const DeformationModel& model, int slots, int max_frames,
                           const ParallelSolvePlan* parallel = nullptr);

  // One scratch for one batch; empty when every scratch is leased. Returned on destruction.
  class Lease {
   public:
    Lease() = default;
    Lease(Lease&& other) noexcept;
    Lease& operator=(Lease&& other) = delete;
    ~Lease();
    explicit operator bool() const { return scratch_ != nullptr; }
    DeformBatchScratch* get() const { return scratch_; }

   private:
    friend class BatchScratchPool;
    Lease(DeformBatchScratch* scratch, std::atomic<bool>* busy) : scratch_(scratch), busy_(busy) {}
    DeformBatchScratch* scratch_ = nullptr;
    std::atomic<bool>* busy_ = nullptr;
  };
  Lease TryAcquire() const;

  int max_frames() const { return max_frames_; }

 private:
  const int max_frames_;
  mutable std::vector<DeformBatchScratch> scratches_;
  mutable std::unique_ptr<std::atomic<bool>[]> busy_;  // one flag per scratch
};

}  // namespace deform::service
