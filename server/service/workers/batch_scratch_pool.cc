#include "service/workers/batch_scratch_pool.h"

#include <algorithm>
#include <utility>

namespace deform::service {

BatchScratchPool::BatchScratchPool(const DeformationModel& model, int slots, int max_frames,
                                   const ParallelSolvePlan* parallel)
    : max_frames_(std::clamp(max_frames, 1, DeformationModel::kMaxBatchFrames)),
      busy_(std::make_unique<std::atomic<bool>[]>(static_cast<std::size_t>(std::max(slots, 0)))) {
  scratches_.reserve(static_cast<std::size_t>(std::max(slots, 0)));
  for (int i = 0; i < slots; ++i) {
    scratches_.push_back(model.MakeBatchScratch(max_frames_, parallel));
    busy_[i].store(false, std::memory_order_relaxed);
  }
}

std::size_t BatchScratchPool::Bytes(const DeformationModel& model, int slots, int max_frames,
                                    const ParallelSolvePlan* parallel) {
  return static_cast<std::size_t>(std::max(slots, 0)) *
         model.BatchScratchBytes(max_frames, parallel);
}

BatchScratchPool::Lease BatchScratchPool::TryAcquire() const {
  for (std::size_t i = 0; i < scratches_.size(); ++i) {
    bool expected = false;
    if (busy_[i].compare_exchange_strong(expected, true, std::memory_order_acquire)) {
      return Lease(&scratches_[i], &busy_[i]);
    }
  }
  return Lease();
}

BatchScratchPool::Lease::Lease(Lease&& other) noexcept
    : scratch_(std::exchange(other.scratch_, nullptr)),
      busy_(std::exchange(other.busy_, nullptr)) {}

BatchScratchPool::Lease::~Lease() {
  if (busy_ != nullptr) busy_->store(false, std::memory_order_release);
}

}  // namespace deform::service
