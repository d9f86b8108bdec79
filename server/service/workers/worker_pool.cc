#include "service/workers/worker_pool.h"

#include <algorithm>
#include <array>

#include "service/workers/cpu_budget.h"

namespace deform::service {

void FrameTask::RunUrgentBatch(FrameTask* const* others, int count) {
  RunUrgent();
  for (int i = 0; i < count; ++i) others[i]->RunUrgent();
}

int WorkerPool::ResolveThreads(int threads) {
  if (threads <= 0) threads = ReadCpuBudget().workers;
  return std::max(threads, 1);
}

WorkerPool::WorkerPool(int threads, int max_batch) {
  max_batch_ = std::clamp(max_batch, 1, kMaxBatch);
  threads = ResolveThreads(threads);
  max_background_ = std::max(1, threads - 1);
  thread_count_ = threads;
  {
    MutexLock lock(&mutex_);
    running_split_keys_.reserve(static_cast<std::size_t>(threads));
    running_split_queued_.reserve(static_cast<std::size_t>(threads));
  }
  threads_.reserve(threads);
  for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { WorkerLoop(); });
}

WorkerPool::~WorkerPool() {
  Shutdown();
  // Tasks posted after Shutdown() never ran; drop them one by one (the urgent chain iteratively,
  // not by recursive destruction).
  std::shared_ptr<FrameTask> head;
  std::deque<std::function<void()>> background;
  {
    MutexLock lock(&mutex_);
    head = std::move(urgent_head_);
    urgent_tail_ = nullptr;
    background.swap(background_);
  }
  while (head != nullptr) head = std::move(head->next_urgent_);
}

int WorkerPool::idle_workers() {
  MutexLock lock(&mutex_);
  return idle_workers_;
}

void WorkerPool::PostUrgent(std::shared_ptr<FrameTask> task) {
  {
    MutexLock lock(&mutex_);
    FrameTask* const queued = task.get();
    if (urgent_tail_ != nullptr) {
      urgent_tail_->next_urgent_ = std::move(task);
    } else {
      urgent_head_ = std::move(task);
    }
    urgent_tail_ = queued;
  }
  wake_.NotifyOne();
}

void WorkerPool::PostBackground(std::function<void()> task) {
  {
    MutexLock lock(&mutex_);
    background_.push_back(std::move(task));
  }
  wake_.NotifyOne();
}

void WorkerPool::Shutdown() {
  MutexLock join_lock(&join_mutex_);
  {
    MutexLock lock(&mutex_);
    stopping_ = true;
  }
  wake_.NotifyAll();
  for (std::thread& thread : threads_) {
    if (thread.joinable()) thread.join();
  }
}

int WorkerPool::BatchShare(int queued, int idle_workers, int max_batch) {
  const int workers = std::clamp(queued / kMinBatchShare, 1, 1 + std::max(idle_workers, 0));
  return std::clamp((queued + workers - 1) / workers, 1, std::max(max_batch, 1));
}

void WorkerPool::CountQueuedOfRunningLocked() {
  running_split_queued_.assign(running_split_keys_.size(), 0);  // within the reserved capacity
  if (running_split_keys_.empty()) return;
  int scanned = 0;
  for (const FrameTask* t = urgent_head_.get(); t != nullptr && scanned < kBatchScanLimit;
       t = t->next_urgent_.get(), ++scanned) {
    const void* key = t->BatchKey();
    for (std::size_t i = 0; i < running_split_keys_.size(); ++i) {
      if (running_split_keys_[i] == key) ++running_split_queued_[i];
    }
  }
}

bool WorkerPool::WaitsForItsBatchLocked(const FrameTask& task) {
  if (running_split_keys_.empty() || max_batch_ <= 1) return false;
  const void* key = task.BatchKey();
  if (key == nullptr || !task.SplitsItsBatches()) return false;
  const auto running = std::find(running_split_keys_.begin(), running_split_keys_.end(), key);
  if (running == running_split_keys_.end()) return false;
  // A whole batch of the key queued runs alongside.
  return running_split_queued_[running - running_split_keys_.begin()] < max_batch_;
}

std::shared_ptr<FrameTask> WorkerPool::TakeUrgentLocked(std::shared_ptr<FrameTask>* others,
                                                        int* count, const void** split_key) {
  *count = 0;
  *split_key = nullptr;
  // The first task that may run now, unlinked through the link that owns it.
  CountQueuedOfRunningLocked();
  std::shared_ptr<FrameTask>* at = &urgent_head_;
  FrameTask* before = nullptr;
  for (int scanned = 0; *at != nullptr && WaitsForItsBatchLocked(**at); ++scanned) {
    if (scanned + 1 >= kBatchScanLimit) return nullptr;
    before = at->get();
    at = &(*at)->next_urgent_;
  }
  if (*at == nullptr) return nullptr;
  std::shared_ptr<FrameTask> head = std::move(*at);
  *at = std::move(head->next_urgent_);
  if (urgent_tail_ == head.get()) urgent_tail_ = before;
  const void* key = max_batch_ > 1 ? head->BatchKey() : nullptr;
  if (key == nullptr) return head;
  // The batch's share of the queued tasks with its key (BatchShare): the workers now idle will
  // take the rest. A split batch takes them all (header comment).
  int matching = 0;
  int scanned = 0;
  for (const FrameTask* task = urgent_head_.get(); task != nullptr && scanned < kBatchScanLimit;
       task = task->next_urgent_.get(), ++scanned) {
    if (task->BatchKey() == key) ++matching;
  }
  const bool splits = head->SplitsItsBatches();
  const int take = (splits ? std::min(1 + matching, max_batch_)
                           : BatchShare(1 + matching, idle_workers_, max_batch_)) -
                   1;
  if (splits) {
    running_split_keys_.push_back(key);
    *split_key = key;
  }
  // Walk the queue through the links that own each task, unlinking the first `take` matches.
  std::shared_ptr<FrameTask>* link = &urgent_head_;
  FrameTask* previous = nullptr;
  for (scanned = 0; *link != nullptr && scanned < kBatchScanLimit && *count < take; ++scanned) {
    if ((*link)->BatchKey() != key) {
      previous = link->get();
      link = &(*link)->next_urgent_;
      continue;
    }
    std::shared_ptr<FrameTask> taken = std::move(*link);
    *link = std::move(taken->next_urgent_);
    if (urgent_tail_ == taken.get()) urgent_tail_ = previous;
    others[(*count)++] = std::move(taken);
  }
  return head;
}

void WorkerPool::WorkerLoop() {
  MutexLock lock(&mutex_);
  while (true) {
    const bool can_run_background = !background_.empty() && running_background_ < max_background_;
    // The background queue's guaranteed worker (header comment).
    const bool background_owed =
        can_run_background && running_background_ == 0 && thread_count_ > 1;
    std::array<std::shared_ptr<FrameTask>, kMaxBatch - 1> others;
    int count = 0;
    const void* split_key = nullptr;  // a split batch's, marked running by TakeUrgentLocked
    std::shared_ptr<FrameTask> task = urgent_head_ != nullptr && !background_owed
                                          ? TakeUrgentLocked(others.data(), &count, &split_key)
                                          : nullptr;
    if (task != nullptr) {
      lock.Unlock();
      if (count == 0) {
        task->RunUrgent();
      } else {
        std::array<FrameTask*, kMaxBatch - 1> members;
        for (int i = 0; i < count; ++i) members[i] = others[i].get();
        task->RunUrgentBatch(members.data(), count);
      }
      // The queue's references go outside the lock.
      task = nullptr;
      for (int i = 0; i < count; ++i) others[i] = nullptr;
      lock.Lock();
      if (split_key != nullptr) {
        running_split_keys_.erase(
            std::find(running_split_keys_.begin(), running_split_keys_.end(), split_key));
        // Its key's tasks that waited may run now, on this worker or an idle one.
        if (urgent_head_ != nullptr) wake_.NotifyOne();
      }
      continue;
    }
    if (can_run_background) {
      std::function<void()> task = std::move(background_.front());
      background_.pop_front();
      ++running_background_;
      lock.Unlock();
      task();
      task = nullptr;  // destroy captures outside the lock
      lock.Lock();
      --running_background_;
      // A worker waiting only because of the background cap may go now.
      if (!background_.empty()) wake_.NotifyOne();
      continue;
    }
    // Stop once nothing is queued (tasks waiting for their key's split batch included: its worker
    // wakes one of the others when it ends) and no background task can still post more work.
    if (stopping_ && urgent_head_ == nullptr && background_.empty() && running_background_ == 0) {
      wake_.NotifyAll();
      return;
    }
    ++idle_workers_;
    wake_.Wait(&mutex_);
    --idle_workers_;
  }
}

}  // namespace deform::service
