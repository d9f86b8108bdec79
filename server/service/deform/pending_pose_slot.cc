#include "service/deform/pending_pose_slot.h"

#include <cassert>
#include <utility>

namespace deform::service {

bool PendingPoseSlot::Offer(PoseInput* pose) {
  if (has_pending_) ++skipped_;
  std::swap(*pose, pending_);
  has_pending_ = true;
  if (task_ != Task::kIdle) return false;
  task_ = Task::kQueued;
  return true;
}

void PendingPoseSlot::BeginRun() {
  assert(task_ == Task::kQueued && "BeginRun without a posted task");
  task_ = Task::kRunning;
}

std::optional<std::uint64_t> PendingPoseSlot::Take(PoseInput* working) {
  if (!has_pending_) return std::nullopt;
  std::swap(pending_, *working);
  has_pending_ = false;
  return std::exchange(skipped_, 0);
}

bool PendingPoseSlot::EndRun(bool may_continue) {
  assert(task_ == Task::kRunning && "EndRun without BeginRun");
  if (has_pending_ && may_continue) {
    task_ = Task::kQueued;
    return true;
  }
  task_ = Task::kIdle;
  return false;
}

}  // namespace deform::service
