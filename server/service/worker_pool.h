// A fixed pool of worker threads for everything that must not run on gRPC's threads: per-frame
// solves (urgent) and mesh precomputation or refactorisation (background).
//
// Scheduling: urgent tasks always go first, in FIFO order. Background tasks run in FIFO order on
// at most max(1, threads - 1) workers at once, so with two or more workers one of them is always
// free for frames while meshes are being built.
//
// Thread safety: every method may be called from any thread, including from inside a task.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace deform::service {

// Work that is posted again and again (one per stream), so queuing it allocates nothing: the
// pool links tasks through `next_urgent_`. A task must not be posted while it is already queued
// (its owner tracks that) and must stay alive until RunUrgent() has been called.
class UrgentTask {
 public:
  virtual void RunUrgent() = 0;

 protected:
  ~UrgentTask() = default;

 private:
  friend class WorkerPool;
  UrgentTask* next_urgent_ = nullptr;
};

class WorkerPool {
 public:
  // `threads` <= 0 means std::thread::hardware_concurrency() (at least 1).
  explicit WorkerPool(int threads);
  // Calls Shutdown().
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int size() const { return static_cast<int>(threads_.size()); }

  // Queues `task` at urgent priority. Allocation-free. Ignored after Shutdown() has finished.
  void PostUrgent(UrgentTask* task);
  // Queues `task` at background priority.
  void PostBackground(std::function<void()> task);

  // Runs every task already queued (and those they post), then joins the workers. Idempotent.
  void Shutdown();

 private:
  void WorkerLoop();

  std::mutex mutex_;
  std::condition_variable wake_;
  UrgentTask* urgent_head_ = nullptr;             // guarded by mutex_
  UrgentTask* urgent_tail_ = nullptr;             // guarded by mutex_
  std::deque<std::function<void()>> background_;  // guarded by mutex_
  int running_background_ = 0;                    // guarded by mutex_
  int max_background_ = 1;
  bool stopping_ = false;  // guarded by mutex_
  std::vector<std::thread> threads_;
  std::mutex join_mutex_;
};

}  // namespace deform::service
