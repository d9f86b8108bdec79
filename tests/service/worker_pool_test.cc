#include "service/worker_pool.h"

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

class FunctionTask final : public UrgentTask {
 public:
  explicit FunctionTask(std::function<void()> body) : body_(std::move(body)) {}
  void RunUrgent() override { body_(); }

 private:
  std::function<void()> body_;
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

TEST(WorkerPoolTest, UrgentTasksOvertakeQueuedBackgroundTasks) {
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

TEST(WorkerPoolTest, BackgroundWorkLeavesOneWorkerForUrgentTasks) {
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
class EndlessUrgentTask final : public UrgentTask,
                                public std::enable_shared_from_this<EndlessUrgentTask> {
 public:
  EndlessUrgentTask(WorkerPool* pool, std::atomic<bool>* stop) : pool_(pool), stop_(stop) {}
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
  for (int i = 0; i < 4; ++i) pool.PostUrgent(std::make_shared<EndlessUrgentTask>(&pool, &stop));
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
TEST(WorkerPoolTest, PoolHoldsEachUrgentTaskUntilItHasRun) {
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
TEST(WorkerPoolTest, UrgentTaskMayRepostItselfWhileRunning) {
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
