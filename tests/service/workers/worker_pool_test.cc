#include "service/workers/worker_pool.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tests/service/support/function_task.h"

namespace deform::service {
namespace {

// A one-shot gate tests open explicitly (no sleeps).
class Gate {
 public:
  void Open() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    cv_.notify_all();
  }
  bool Wait(std::chrono::seconds timeout = std::chrono::seconds(60)) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, timeout, [this] { return open_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool open_ = false;
};

class EventLog {
 public:
  void Add(const std::string& event) {
    std::lock_guard<std::mutex> lock(mutex_);
    events_.push_back(event);
  }
  std::vector<std::string> events() {
    std::lock_guard<std::mutex> lock(mutex_);
    return events_;
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> events_;
};

// A task with a batch key; its batch runs record which tasks ran together.
class KeyedTask final : public FrameTask {
 public:
  KeyedTask(std::string name, const void* key, EventLog* log)
      : name_(std::move(name)), key_(key), log_(log) {}
  void RunUrgent() override { log_->Add(name_); }
  const void* BatchKey() const override { return key_; }
  void RunUrgentBatch(FrameTask* const* others, int count) override {
    std::string batch = name_;
    for (int i = 0; i < count; ++i) batch += "+" + static_cast<KeyedTask*>(others[i])->name_;
    log_->Add(batch);
  }

 private:
  std::string name_;
  const void* key_;
  EventLog* log_;
};

// One worker held busy while tasks queue, so the batches formed are deterministic.
struct BlockedPool {
  explicit BlockedPool(int max_batch) : pool(1, max_batch) {
    blocker = std::make_shared<FunctionTask>([this] {
      running.Open();
      release.Wait();
    });
    pool.PostUrgent(blocker);
    EXPECT_TRUE(running.Wait());
  }
  WorkerPool pool;
  Gate running, release;
  std::shared_ptr<FunctionTask> blocker;
};

TEST(WorkerPoolTest, QueuedTasksWithTheSameKeyRunAsOneBatchUpToTheLimit) {
  EventLog log;
  int mesh_a = 0, mesh_b = 0;
  BlockedPool blocked(3);
  std::vector<std::shared_ptr<KeyedTask>> tasks = {
      std::make_shared<KeyedTask>("a1", &mesh_a, &log),
      std::make_shared<KeyedTask>("b1", &mesh_b, &log),
      std::make_shared<KeyedTask>("a2", &mesh_a, &log),
      std::make_shared<KeyedTask>("none", nullptr, &log),
      std::make_shared<KeyedTask>("a3", &mesh_a, &log),
      std::make_shared<KeyedTask>("a4", &mesh_a, &log),
      std::make_shared<KeyedTask>("b2", &mesh_b, &log)};
  for (const auto& task : tasks) blocked.pool.PostUrgent(task);
  blocked.release.Open();
  blocked.pool.Shutdown();
  // a1 takes a2 and a3 (three at most); b1 takes b2; a task without a key runs alone, in order.
  EXPECT_EQ(log.events(), (std::vector<std::string>{"a1+a2+a3", "b1+b2", "none", "a4"}));
}

TEST(WorkerPoolTest, ABatchLimitOfOneNeverBatches) {
  EventLog log;
  int mesh = 0;
  BlockedPool blocked(1);
  for (const char* name : {"a1", "a2", "a3"}) {
    blocked.pool.PostUrgent(std::make_shared<KeyedTask>(name, &mesh, &log));
  }
  blocked.release.Open();
  blocked.pool.Shutdown();
  EXPECT_EQ(log.events(), (std::vector<std::string>{"a1", "a2", "a3"}));
}

TEST(WorkerPoolTest, ABatchTakenFromTheQueuesTailLeavesItUsable) {
  EventLog log;
  int mesh_a = 0, mesh_b = 0;
  BlockedPool blocked(4);
  blocked.pool.PostUrgent(std::make_shared<KeyedTask>("a1", &mesh_a, &log));
  blocked.pool.PostUrgent(std::make_shared<KeyedTask>("b1", &mesh_b, &log));
  blocked.pool.PostUrgent(std::make_shared<KeyedTask>("a2", &mesh_a, &log));  // the tail
  blocked.release.Open();
  // Posted while the queue's tail may just have been taken by a batch.
  blocked.pool.PostUrgent(std::make_shared<KeyedTask>("b2", &mesh_b, &log));
  blocked.pool.Shutdown();
  const std::vector<std::string> events = log.events();
  ASSERT_GE(events.size(), 2u);
  EXPECT_EQ(events[0], "a1+a2");
  // b2 either joined b1's batch or ran after it; none was lost.
  if (events.size() == 2) {
    EXPECT_EQ(events[1], "b1+b2");
  } else {
    EXPECT_EQ(events, (std::vector<std::string>{"a1+a2", "b1", "b2"}));
  }
}

// A worker's share of the queued tasks of one key: spread over the idle workers only while each
// gets at least kMinBatchShare, never more than the batch limit, never less than the head.
TEST(WorkerPoolTest, ABatchIsSharedWithIdleWorkersOnlyInWorthwhileShares) {
  static_assert(WorkerPool::kMinBatchShare == 4, "the cases below are written for four");
  EXPECT_EQ(WorkerPool::BatchShare(1, 1, 8), 1);
  EXPECT_EQ(WorkerPool::BatchShare(2, 1, 8), 2);    // not split into two lone tasks
  EXPECT_EQ(WorkerPool::BatchShare(7, 1, 8), 7);    // 4 + 3: the second share too small
  EXPECT_EQ(WorkerPool::BatchShare(8, 1, 8), 4);    // 4 + 4
  EXPECT_EQ(WorkerPool::BatchShare(9, 1, 8), 5);    // 5 + 4
  EXPECT_EQ(WorkerPool::BatchShare(8, 0, 8), 8);    // nobody to share with
  EXPECT_EQ(WorkerPool::BatchShare(12, 2, 16), 4);  // three workers, four each
  EXPECT_EQ(WorkerPool::BatchShare(12, 5, 16), 4);  // no more workers than shares of four
  EXPECT_EQ(WorkerPool::BatchShare(20, 0, 8), 8);   // the batch limit
  EXPECT_EQ(WorkerPool::BatchShare(20, 0, 1), 1);
}

// A task of a key whose batches split their work (a big mesh's frames): records its batch when the
// batch ends, after `before_end` (if any) has returned.
class SplitTask final : public FrameTask {
 public:
  SplitTask(std::string name, const void* key, EventLog* log,
            std::function<void()> before_end = nullptr)
      : name_(std::move(name)), key_(key), log_(log), before_end_(std::move(before_end)) {}
  void RunUrgent() override { RunUrgentBatch(nullptr, 0); }
  const void* BatchKey() const override { return key_; }
  bool SplitsItsBatches() const override { return true; }
  void RunUrgentBatch(FrameTask* const* others, int count) override {
    if (before_end_) before_end_();
    std::string batch = name_;
    for (int i = 0; i < count; ++i) batch += "+" + static_cast<SplitTask*>(others[i])->name_;
    log_->Add(batch);
  }

 private:
  std::string name_;
  const void* key_;
  EventLog* log_;
  std::function<void()> before_end_;
};

// Polls `condition` until it holds or a minute has passed.
bool Eventually(const std::function<bool()>& condition) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// While a split batch runs, the other worker leaves its key's queued tasks alone (they make the
// next batch, all of them) but runs other work, and otherwise waits idle, where the batch's
// helpers would find it.
TEST(WorkerPoolTest, ASplitBatchRunsOneAtATimeWhileTheOtherWorkersWaitIdle) {
  WorkerPool pool(2, 4);
  EventLog log;
  int mesh = 0;
  Gate started, release;
  pool.PostUrgent(std::make_shared<SplitTask>("s1", &mesh, &log, [&] {
    started.Open();
    release.Wait();
  }));
  ASSERT_TRUE(started.Wait());
  pool.PostUrgent(std::make_shared<SplitTask>("s2", &mesh, &log));
  pool.PostUrgent(std::make_shared<SplitTask>("s3", &mesh, &log));
  pool.PostUrgent(std::make_shared<FunctionTask>([&] { log.Add("other"); }));
  EXPECT_TRUE(Eventually([&] { return log.events().size() == 1; }));
  EXPECT_TRUE(Eventually([&] { return pool.idle_workers() == 1; }));
  EXPECT_EQ(log.events(), (std::vector<std::string>{"other"}));  // s2 and s3 still queued
  release.Open();
  pool.Shutdown();
  EXPECT_EQ(log.events(), (std::vector<std::string>{"other", "s1", "s2+s3"}));
}

// A whole batch (the pool's limit) of a split key queued runs alongside the running one.
TEST(WorkerPoolTest, AWholeBatchOfASplitKeyRunsAlongsideTheRunningOne) {
  WorkerPool pool(2, 2);
  EventLog log;
  int mesh = 0;
  Gate started, release;
  pool.PostUrgent(std::make_shared<SplitTask>("s1", &mesh, &log, [&] {
    started.Open();
    release.Wait();
  }));
  ASSERT_TRUE(started.Wait());
  pool.PostUrgent(std::make_shared<SplitTask>("s2", &mesh, &log));
  pool.PostUrgent(std::make_shared<SplitTask>("s3", &mesh, &log));
  EXPECT_TRUE(Eventually([&] { return log.events().size() == 1; }));
  EXPECT_EQ(log.events(), (std::vector<std::string>{"s2+s3"}));
  release.Open();
  pool.Shutdown();
  EXPECT_EQ(log.events(), (std::vector<std::string>{"s2+s3", "s1"}));
}

TEST(WorkerPoolTest, ALoneTaskWithAKeyRunsWithoutWaitingForOthers) {
  WorkerPool pool(2, 8);
  int mesh = 0;
  Gate ran;
  class Signalling final : public FrameTask {
   public:
    Signalling(const void* key, Gate* gate) : key_(key), gate_(gate) {}
    void RunUrgent() override { gate_->Open(); }
    const void* BatchKey() const override { return key_; }

   private:
    const void* key_;
    Gate* gate_;
  };
  pool.PostUrgent(std::make_shared<Signalling>(&mesh, &ran));
  EXPECT_TRUE(ran.Wait());
  pool.Shutdown();
}

TEST(WorkerPoolTest, FrameTasksOvertakeQueuedBackgroundTasks) {
  WorkerPool pool(1);
  EventLog log;
  Gate blocker_running, release_blocker;
  pool.PostBackground([&] {
    blocker_running.Open();
    release_blocker.Wait();
    log.Add("blocker");
  });
  ASSERT_TRUE(blocker_running.Wait());
  pool.PostBackground([&] { log.Add("background"); });
  auto urgent = std::make_shared<FunctionTask>([&] { log.Add("urgent"); });
  pool.PostUrgent(urgent);
  release_blocker.Open();
  pool.Shutdown();
  EXPECT_EQ(log.events(), (std::vector<std::string>{"blocker", "urgent", "background"}));
}

TEST(WorkerPoolTest, BackgroundWorkLeavesOneWorkerForFrameTasks) {
  WorkerPool pool(2);
  EventLog log;
  Gate first_running, release_first, urgent_ran;
  std::atomic<bool> second_started{false};
  pool.PostBackground([&] {
    first_running.Open();
    release_first.Wait();
    log.Add("first");
  });
  ASSERT_TRUE(first_running.Wait());
  pool.PostBackground([&] {
    second_started.store(true);
    log.Add("second");
  });
  auto urgent = std::make_shared<FunctionTask>([&] {
    log.Add("urgent");
    urgent_ran.Open();
  });
  pool.PostUrgent(urgent);
  // The second worker is free for the urgent task, but may not take the second background task.
  ASSERT_TRUE(urgent_ran.Wait());
  EXPECT_FALSE(second_started.load());
  release_first.Open();
  pool.Shutdown();
  EXPECT_EQ(log.events(), (std::vector<std::string>{"urgent", "first", "second"}));
}

// Urgent work that never lets up: runs, then posts itself again until stopped.
class EndlessFrameTask final : public FrameTask,
                               public std::enable_shared_from_this<EndlessFrameTask> {
 public:
  EndlessFrameTask(WorkerPool* pool, std::atomic<bool>* stop) : pool_(pool), stop_(stop) {}
  void RunUrgent() override {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    if (!stop_->load()) pool_->PostUrgent(shared_from_this());
  }

 private:
  WorkerPool* const pool_;
  std::atomic<bool>* const stop_;
};

TEST(WorkerPoolTest, BackgroundWorkRunsHoweverBusyUrgentWorkKeepsThePool) {
  WorkerPool pool(2);
  std::atomic<bool> stop{false};
  // More urgent work than workers, queued at every moment.
  for (int i = 0; i < 4; ++i) pool.PostUrgent(std::make_shared<EndlessFrameTask>(&pool, &stop));
  Gate background_ran;
  pool.PostBackground([&] { background_ran.Open(); });
  EXPECT_TRUE(background_ran.Wait()) << "the background task was starved";
  stop.store(true);
  pool.Shutdown();
}

TEST(WorkerPoolTest, ShutdownRunsEverythingQueuedIncludingWorkPostedByTasks) {
  std::atomic<int> runs{0};
  auto urgent = std::make_shared<FunctionTask>([&] { runs.fetch_add(1); });
  {
    WorkerPool pool(2);
    for (int i = 0; i < 50; ++i) {
      pool.PostBackground([&] {
        runs.fetch_add(1);
        if (runs.load() == 10) pool.PostUrgent(urgent);
      });
    }
    pool.Shutdown();
    pool.Shutdown();  // idempotent
  }
  EXPECT_EQ(runs.load(), 51);
}

// The pool's reference keeps a task alive until it has run, and is dropped after it: the task may
// be its own last owner (as a stream reactor is once gRPC is done with it).
TEST(WorkerPoolTest, PoolHoldsEachFrameTaskUntilItHasRun) {
  WorkerPool pool(1);
  Gate blocker_running, release_blocker;
  pool.PostBackground([&] {
    blocker_running.Open();
    release_blocker.Wait();
  });
  ASSERT_TRUE(blocker_running.Wait());
  std::atomic<int> runs{0};
  auto task = std::make_shared<FunctionTask>([&] { runs.fetch_add(1); });
  const std::weak_ptr<FunctionTask> watch = task;
  pool.PostUrgent(std::move(task));
  EXPECT_FALSE(watch.expired());  // queued behind the blocker: only the pool owns it
  release_blocker.Open();
  pool.Shutdown();
  EXPECT_EQ(runs.load(), 1);
  EXPECT_TRUE(watch.expired());
}

// A task may post itself again while it runs (a stream with another pose pending does).
TEST(WorkerPoolTest, FrameTaskMayRepostItselfWhileRunning) {
  WorkerPool pool(2);
  std::atomic<int> runs{0};
  std::shared_ptr<FunctionTask> task;
  std::weak_ptr<FunctionTask> self;
  task = std::make_shared<FunctionTask>([&] {
    if (runs.fetch_add(1) + 1 < 5) pool.PostUrgent(self.lock());
  });
  self = task;
  pool.PostUrgent(std::move(task));
  pool.Shutdown();
  EXPECT_EQ(runs.load(), 5);
  EXPECT_TRUE(self.expired());
}

TEST(WorkerPoolTest, ZeroThreadsMeansOnePerCore) {
  WorkerPool pool(0);
  EXPECT_GE(pool.size(), 1);
}

}  // namespace
}  // namespace deform::service
