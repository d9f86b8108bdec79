// A fixed pool of worker threads for everything that must not run on gRPC's threads: per-frame
// solves (urgent) and mesh precomputation or refactorization (background).
//
// Scheduling: two queues, each in FIFO order. Background tasks run on at most max(1, threads - 1)
// workers at once, so with two or more workers one of them is always free for frames while
// meshes are being built. Urgent tasks go first, except that with two or more workers a queued
// background task is owed a worker whenever none is running one: a worker that becomes free takes
// it before the next urgent task, so builds and refactorizations progress however busy the frames
// keep the pool (a guaranteed share of one worker). With one worker urgent tasks always go first.
//
// Batches: an urgent task may name a batch key (FrameTask::BatchKey). A worker that takes such a
// task from the head of the queue also takes queued tasks with the same key and hands them to the
// first task's RunUrgentBatch, which runs them all: its share of them when other workers are idle
// and the tasks are enough for a worthwhile batch each (those take the rest, so many tasks are
// spread over the free workers; BatchShare), up to the pool's max_batch in all, looking at most
// kBatchScanLimit tasks deep. Nothing waits for a batch to fill: a batch is only what is already
// queued, so a lone task runs as soon as a worker is free, as before.
//
// Split batches: tasks whose key's batches split their own work over the idle workers
// (FrameTask::SplitsItsBatches, a big mesh's solves) run one batch of a key at a time. Their
// batch takes every queued task of its key (up to max_batch, no share left for idle workers),
// and while it runs the other workers leave the key's tasks queued, taking other work or waiting
// idle, where the running batch's helpers (posted to the queue when it began) find them; unless a
// whole batch (max_batch tasks) of the key is queued, which then runs alongside. So the frames that
// arrive during a batch make the next one, solved on every free core, instead of smaller batches
// side by side each on one core.
//
// Ownership: the pool holds a reference to every task it has been given (the urgent task's
// shared_ptr, the background task's function and its captures) until the task has run, and drops
// it outside its lock, so a task's reference can be the last one to its owner (a stream reactor).
//
// Thread safety: every method may be called from any thread, including from inside a task.
#pragma once

#include <deque>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

#include "service/base/annotated_mutex.h"
#include "service/base/thread_annotations.h"

namespace deform::service {

// Work that is posted again and again (one per stream), so queuing it allocates nothing: the
// pool links tasks through `next_urgent_`. A task must not be posted while it is already queued
// (its owner tracks that); it may be posted again while it runs.
class FrameTask {
 public:
  virtual void RunUrgent() = 0;

  // Tasks with the same non-null key may run as one batch (see the pool's header). The key is
  // read under the pool's lock when the batch is formed, so it must be cheap and thread-safe (an
  // atomic); it may be stale, and RunUrgentBatch must cope with a member whose key has changed
  // since. Tasks that share a key must be of one type (RunUrgentBatch may downcast them).
  virtual const void* BatchKey() const { return nullptr; }
  // Whether the batches of this task's key split their work over the pool's idle workers (see the
  // pool's header); read with BatchKey, the same for every task of a key, cheap and thread-safe.
  virtual bool SplitsItsBatches() const { return false; }
  // Runs this task and `others` (`count` tasks taken from the queue with this task's key): each
  // must get what its own RunUrgent() would give it. The default runs them one after the other.
  virtual void RunUrgentBatch(FrameTask* const* others, int count);

 protected:
  ~FrameTask() = default;

 private:
  friend class WorkerPool;
  std::shared_ptr<FrameTask> next_urgent_;  // the queue's reference to the next task
};

class WorkerPool {
 public:
  // Tasks a batch may look past at the queue's head when it gathers tasks with its key.
  static constexpr int kBatchScanLimit = 64;
  // Largest batch a pool forms.
  static constexpr int kMaxBatch = 16;
  // Smallest share of a batch handed to a worker of its own: the queued tasks of one key are
  // spread over the idle workers only while each still gets this many. A batched solve's cost per
  // frame falls with its size (docs/performance.md, "Batched solves"), so splitting fewer than
  // 2 x kMinBatchShare frames puts frames on a worker at well above their batched cost, which a
  // busy server pays for in frames it cannot deliver.
  static constexpr int kMinBatchShare = 4;
  // How many of `queued` tasks of one key (the head included) the worker taking the head runs as
  // its batch when `idle_workers` others are idle: its even share over as many workers as can each
  // get kMinBatchShare (at least itself), at most `max_batch`.
  static int BatchShare(int queued, int idle_workers, int max_batch);

  // `threads` <= 0 means the CPUs this process may use (ReadCpuBudget: its affinity and cgroup
  // CPU quota, cpu_budget.h). `max_batch`: tasks run
  // together at most, clamped to [1, kMaxBatch]; 1 never batches.
  explicit WorkerPool(int threads, int max_batch = 1);
  // Calls Shutdown(), then drops the tasks posted after it (they never run).
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // The threads a pool of `threads` runs: `threads`, or the number of cores when <= 0 (>= 1).
  static int ResolveThreads(int threads);

  int size() const { return thread_count_; }
  int max_batch() const { return max_batch_; }
  // Workers waiting for work at this moment (a hint: it may change as soon as it is read).
  int idle_workers() DEFORM_EXCLUDES(mutex_);

  // Queues `task` at urgent priority; the pool keeps it alive until RunUrgent() has returned.
  // Allocation-free. After Shutdown() has finished the task is kept but never runs.
  void PostUrgent(std::shared_ptr<FrameTask> task) DEFORM_EXCLUDES(mutex_);
  // Queues `task` at background priority. After Shutdown() has finished it never runs.
  void PostBackground(std::function<void()> task) DEFORM_EXCLUDES(mutex_);

  // Runs every task already queued (and those they post), then joins the workers. Idempotent.
  void Shutdown() DEFORM_EXCLUDES(mutex_, join_mutex_);

 private:
  void WorkerLoop() DEFORM_EXCLUDES(mutex_);
  // Unlinks the first urgent task that may run now (not of a split key whose batch is running,
  // header comment) and, when it has a batch key, the queued tasks with the same key (at most
  // max_batch_ - 1, within kBatchScanLimit) into `others`; returns the task, or null when every
  // queued task must wait. `split_key`: the key of a split batch, now marked running, or null.
  std::shared_ptr<FrameTask> TakeUrgentLocked(std::shared_ptr<FrameTask>* others, int* count,
                                              const void** split_key) DEFORM_REQUIRES(mutex_);
  // Counts the queued tasks of each running split batch's key (within kBatchScanLimit) into
  // running_split_queued_: one pass over the queue for all of them.
  void CountQueuedOfRunningLocked() DEFORM_REQUIRES(mutex_);
  // Whether `task` waits for its key's running split batch (header comment), by the counts of
  // CountQueuedOfRunningLocked.
  bool WaitsForItsBatchLocked(const FrameTask& task) DEFORM_REQUIRES(mutex_);

  Mutex mutex_;
  CondVar wake_;
  std::shared_ptr<FrameTask> urgent_head_ DEFORM_GUARDED_BY(mutex_);  // owns the queue's chain
  FrameTask* urgent_tail_ DEFORM_GUARDED_BY(mutex_) = nullptr;
  std::deque<std::function<void()>> background_ DEFORM_GUARDED_BY(mutex_);
  int running_background_ DEFORM_GUARDED_BY(mutex_) = 0;
  int idle_workers_ DEFORM_GUARDED_BY(mutex_) = 0;  // waiting for work
  // The keys of the split batches running (one entry per running batch; capacity reserved for
  // every worker, so it never allocates).
  std::vector<const void*> running_split_keys_ DEFORM_GUARDED_BY(mutex_);
  // Per running split key, its tasks queued (CountQueuedOfRunningLocked); the same capacity.
  std::vector<int> running_split_queued_ DEFORM_GUARDED_BY(mutex_);
  int max_background_ = 1;  // set by the constructor, then read-only
  bool stopping_ DEFORM_GUARDED_BY(mutex_) = false;

  int thread_count_ = 0;  // set by the constructor, then read-only
  int max_batch_ = 1;     // set by the constructor, then read-only
  Mutex join_mutex_;      // serializes Shutdown()
  std::vector<std::thread> threads_ DEFORM_GUARDED_BY(join_mutex_);
};

}  // namespace deform::service
