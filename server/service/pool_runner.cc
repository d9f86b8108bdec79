#include "service/pool_runner.h"

#include <algorithm>

namespace deform::service {

// The computation being run; parts are taken in order under the mutex.
struct PoolRunner::Job {
  std::mutex mutex;
  std::condition_variable finished_part;
  void (*part)(void*, int) = nullptr;  // null: no computation open
  void* context = nullptr;
  int count = 0;
  int next = 0;
  int finished = 0;

  // Takes and runs parts until none is left; `lock` holds `mutex`.
  void RunParts(std::unique_lock<std::mutex>& lock) {
    while (part != nullptr && next < count) {
      const int index = next++;
      void (*const run)(void*, int) = part;
      void* const argument = context;
      lock.unlock();
      run(argument, index);
      lock.lock();
      ++finished;
      finished_part.notify_all();
    }
  }
};

class PoolRunner::Helper final : public UrgentTask {
 public:
  explicit Helper(std::shared_ptr<Job> job) : job_(std::move(job)) {}
  // Whether it is queued on the pool; guarded by the job's mutex.
  bool queued = false;

  void RunUrgent() override {
    std::unique_lock<std::mutex> lock(job_->mutex);
    queued = false;
    job_->RunParts(lock);
  }

 private:
  std::shared_ptr<Job> job_;
};

PoolRunner::PoolRunner(WorkerPool* pool) : pool_(pool), job_(std::make_shared<Job>()) {
  for (int i = 1; i < pool->size(); ++i) helpers_.push_back(std::make_shared<Helper>(job_));
}

PoolRunner::~PoolRunner() = default;

int PoolRunner::IdleHelpers() {
  return std::min(pool_->idle_workers(), static_cast<int>(helpers_.size()));
}

void PoolRunner::Run(int count, void (*part)(void* context, int index), void* context) {
  std::unique_lock<std::mutex> lock(job_->mutex);
  job_->part = part;
  job_->context = context;
  job_->count = count;
  job_->next = 0;
  job_->finished = 0;
  int wanted = count - 1;
  for (const std::shared_ptr<Helper>& helper : helpers_) {
    if (wanted <= 0) break;
    if (helper->queued) continue;  // still queued from an earlier computation: it will help
    helper->queued = true;
    --wanted;
    pool_->PostUrgent(helper);  // takes the pool's lock, never the job's: no lock-order cycle
  }
  job_->RunParts(lock);
  job_->finished_part.wait(lock, [&] { return job_->finished == job_->count; });
  job_->part = nullptr;  // a helper starting late finds nothing to run
  job_->context = nullptr;
}

}  // namespace deform::service
