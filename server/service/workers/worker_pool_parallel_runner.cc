#include "service/workers/worker_pool_parallel_runner.h"

#include <algorithm>

#include "service/base/annotated_mutex.h"
#include "service/base/thread_annotations.h"

namespace deform::service {

// A held MutexLock as the BasicLockable the core's PartsInProgress::RunParts takes. RunParts
// releases it only while a part runs and holds it again before it returns, which the analysis
// cannot follow through the core's template: hence unannotated.
class HeldLock {
 public:
  explicit HeldLock(MutexLock* lock) : lock_(lock) {}
  void unlock() DEFORM_NO_THREAD_SAFETY_ANALYSIS { lock_->Unlock(); }
  void lock() DEFORM_NO_THREAD_SAFETY_ANALYSIS { lock_->Lock(); }

 private:
  MutexLock* const lock_;
};

// The computation being run (its parts taken in order under the mutex) and whether each helper is
// queued on the pool.
struct WorkerPoolParallelRunner::Job {
  Mutex mutex;
  CondVar finished_part;
  PartsInProgress parts DEFORM_GUARDED_BY(mutex);

  // Takes and runs parts until none is left; `lock` holds `mutex`.
  void RunParts(MutexLock& lock) DEFORM_REQUIRES(mutex) {
    HeldLock held(&lock);
    parts.RunParts(held, [this] { finished_part.NotifyAll(); });
  }
};

class WorkerPoolParallelRunner::Helper final : public FrameTask {
 public:
  explicit Helper(std::shared_ptr<Job> job) : job_(std::move(job)) {}
  // Whether it is queued on the pool; changed only under the job's mutex.
  bool queued = false;

  void RunUrgent() override {
    MutexLock lock(&job_->mutex);
    queued = false;
    job_->RunParts(lock);
  }

 private:
  std::shared_ptr<Job> job_;
};

WorkerPoolParallelRunner::WorkerPoolParallelRunner(WorkerPool* pool)
    : pool_(pool), job_(std::make_shared<Job>()) {
  for (int i = 1; i < pool->size(); ++i) helpers_.push_back(std::make_shared<Helper>(job_));
}

WorkerPoolParallelRunner::~WorkerPoolParallelRunner() = default;

int WorkerPoolParallelRunner::IdleHelpers() {
  return std::min(pool_->idle_workers(), static_cast<int>(helpers_.size()));
}

void WorkerPoolParallelRunner::Run(int count, void (*part)(void* context, int index),
                                   void* context) {
  MutexLock lock(&job_->mutex);
  job_->parts.Open(count, part, context);
  int wanted = count - 1;
  for (const std::shared_ptr<Helper>& helper : helpers_) {
    if (wanted <= 0) break;
    if (helper->queued) continue;  // still queued from an earlier computation: it will help
    helper->queued = true;
    --wanted;
    pool_->PostUrgent(helper);  // takes the pool's lock, never the job's: no lock-order cycle
  }
  job_->RunParts(lock);
  while (!job_->parts.all_finished()) job_->finished_part.Wait(&job_->mutex);
  job_->parts.Close();  // a helper starting late finds nothing to run
}

}  // namespace deform::service
