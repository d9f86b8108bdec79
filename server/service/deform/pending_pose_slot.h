// The Deform stream's pending pose, and the state of its solve task.
//
// Latest wins: a pose offered while another still waits replaces it, and the replaced pose counts
// as skipped; Take() hands the newest pose to the solve together with the number of poses it
// replaced since the previous Take().
//
// The solve task (one per stream, on the worker pool's urgent queue) is idle, queued or running,
// and at most one is queued or running at a time: Offer() says when the caller must post it,
// EndRun() when it must post it again.
//
//   idle --Offer()--> queued --BeginRun()--> running --EndRun()--> queued (a pose is pending and
//                                                                   the stream goes on) or idle
//
// Buffers are swapped, never copied: once every PoseInput has its capacity nothing allocates.
// Thread safety: none; the stream's lock guards every call. The PoseInput handed out by Take()
// belongs to the solve.
#pragma once

#include <cstdint>
#include <optional>

#include "service/deform/pose_input.h"

namespace deform::service {

class PendingPoseSlot {
 public:
  // Puts `*pose` in the slot and hands the caller the slot's previous buffer to refill. True when
  // the caller must post the solve task (it was idle and is queued now).
  bool Offer(PoseInput* pose);

  // The posted task starts running.
  void BeginRun();
  // Swaps the pending pose into `*working`; the number of poses it replaced since the previous
  // Take(), or nullopt when none is pending.
  std::optional<std::uint64_t> Take(PoseInput* working);
  // The run has ended. True when the caller must post the task again (a pose is pending and
  // `may_continue`; it goes to the back of the queue, for fairness); otherwise the task is idle.
  bool EndRun(bool may_continue);

  bool has_pending() const { return has_pending_; }
  // Between BeginRun() and EndRun(): a solve may be using the stream's factorization.
  bool running() const { return task_ == Task::kRunning; }
  // No task queued or running.
  bool idle() const { return task_ == Task::kIdle; }

 private:
  enum class Task { kIdle, kQueued, kRunning };

  Task task_ = Task::kIdle;
  PoseInput pending_;
  bool has_pending_ = false;
  std::uint64_t skipped_ = 0;  // poses replaced in the slot since the last Take()
};

}  // namespace deform::service
