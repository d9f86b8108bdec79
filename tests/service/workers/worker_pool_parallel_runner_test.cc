#include "service/workers/worker_pool_parallel_runner.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "service/workers/worker_pool.h"
#include "tests/service/support/function_task.h"

namespace deform::service {
namespace {

// Runs `body` on one of `pool`'s workers (as a stream's solve task does) and waits for it.
void RunOnWorker(WorkerPool* pool, const std::function<void()>& body) {
  std::mutex mutex;
  std::condition_variable cv;
  bool done = false;
  pool->PostUrgent(std::make_shared<FunctionTask>([&] {
    body();
    std::lock_guard<std::mutex> lock(mutex);
    done = true;
    cv.notify_all();
  }));
  std::unique_lock<std::mutex> lock(mutex);
  ASSERT_TRUE(cv.wait_for(lock, std::chrono::seconds(60), [&] { return done; }));
}

struct Parts {
  std::vector<std::atomic<int>> runs = std::vector<std::atomic<int>>(16);
  std::mutex mutex;
  std::set<std::thread::id> threads;
  static void Run(void* context, int index) {
    auto* parts = static_cast<Parts*>(context);
    parts->runs[index].fetch_add(1);
    std::lock_guard<std::mutex> lock(parts->mutex);
    parts->threads.insert(std::this_thread::get_id());
  }
};

TEST(WorkerPoolParallelRunnerTest, EveryPartRunsExactlyOnceRunAfterRun) {
  WorkerPool pool(2);
  WorkerPoolParallelRunner runner(&pool);
  RunOnWorker(&pool, [&] {
    for (int round = 0; round < 200; ++round) {
      Parts parts;
      runner.Run(5, &Parts::Run, &parts);
      for (int i = 0; i < 5; ++i) ASSERT_EQ(parts.runs[i].load(), 1) << round << " " << i;
      for (int i = 5; i < 16; ++i) ASSERT_EQ(parts.runs[i].load(), 0);
    }
  });
  pool.Shutdown();
}

// With an idle worker the parts run side by side: the first part waits until another has started
// elsewhere (it would wait forever on one thread; the test then fails on the timeout).
TEST(WorkerPoolParallelRunnerTest, AnIdleWorkerTakesPartsAlongsideTheCaller) {
  WorkerPool pool(2);
  WorkerPoolParallelRunner runner(&pool);
  struct Rendezvous {
    std::mutex mutex;
    std::condition_variable cv;
    std::set<std::thread::id> threads;
    bool met = false;
    static void Run(void* context, int) {
      auto* r = static_cast<Rendezvous*>(context);
      std::unique_lock<std::mutex> lock(r->mutex);
      r->threads.insert(std::this_thread::get_id());
      if (r->threads.size() >= 2) r->met = true;
      r->cv.notify_all();
      r->cv.wait_for(lock, std::chrono::seconds(10), [&] { return r->met; });
    }
  } rendezvous;
  // Both workers waiting first (a worker not yet started is not idle, and gets no helper).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (pool.idle_workers() < 2 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_EQ(pool.idle_workers(), 2);
  RunOnWorker(&pool, [&] { runner.Run(2, &Rendezvous::Run, &rendezvous); });
  EXPECT_TRUE(rendezvous.met) << "the second part never ran beside the first";
  pool.Shutdown();
}

// With every other worker busy the caller runs every part itself and does not wait for them.
TEST(WorkerPoolParallelRunnerTest, ABusyPoolLeavesEveryPartToTheCaller) {
  WorkerPool pool(2);
  WorkerPoolParallelRunner runner(&pool);
  std::mutex mutex;
  std::condition_variable cv;
  bool busy = false, release = false;
  pool.PostUrgent(std::make_shared<FunctionTask>([&] {
    std::unique_lock<std::mutex> lock(mutex);
    busy = true;
    cv.notify_all();
    cv.wait(lock, [&] { return release; });
  }));
  {
    std::unique_lock<std::mutex> lock(mutex);
    ASSERT_TRUE(cv.wait_for(lock, std::chrono::seconds(60), [&] { return busy; }));
  }
  Parts parts;
  RunOnWorker(&pool, [&] { runner.Run(4, &Parts::Run, &parts); });
  for (int i = 0; i < 4; ++i) EXPECT_EQ(parts.runs[i].load(), 1);
  EXPECT_EQ(parts.threads.size(), 1u);
  {
    std::lock_guard<std::mutex> lock(mutex);
    release = true;
  }
  cv.notify_all();
  pool.Shutdown();
}

// A worker busy when Run begins still helps once it frees up: its helper was posted all the same.
// The first part frees the busy worker, then waits until the second part has started elsewhere
// (on one thread it would wait out its timeout and the test fails).
TEST(WorkerPoolParallelRunnerTest, AWorkerBusyWhenRunBeginsTakesPartsOnceItFreesUp) {
  WorkerPool pool(2);
  WorkerPoolParallelRunner runner(&pool);
  struct Late {
    std::mutex mutex;
    std::condition_variable cv;
    bool busy = false, release = false, second_started = false;
    std::thread::id caller, second;
    static void Run(void* context, int index) {
      auto* l = static_cast<Late*>(context);
      std::unique_lock<std::mutex> lock(l->mutex);
      if (index == 0) {
        l->caller = std::this_thread::get_id();
        l->release = true;
        l->cv.notify_all();
        l->cv.wait_for(lock, std::chrono::seconds(10), [&] { return l->second_started; });
      } else {
        l->second = std::this_thread::get_id();
        l->second_started = true;
        l->cv.notify_all();
      }
    }
  } late;
  pool.PostUrgent(std::make_shared<FunctionTask>([&] {
    std::unique_lock<std::mutex> lock(late.mutex);
    late.busy = true;
    late.cv.notify_all();
    late.cv.wait(lock, [&] { return late.release; });
  }));
  {
    std::unique_lock<std::mutex> lock(late.mutex);
    ASSERT_TRUE(late.cv.wait_for(lock, std::chrono::seconds(60), [&] { return late.busy; }));
  }
  RunOnWorker(&pool, [&] { runner.Run(2, &Late::Run, &late); });
  EXPECT_TRUE(late.second_started);
  EXPECT_NE(late.second, late.caller) << "the second part waited for the caller";
  pool.Shutdown();
}

}  // namespace
}  // namespace deform::service
