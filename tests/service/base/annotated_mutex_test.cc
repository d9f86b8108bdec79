// Mutex, MutexLock and CondVar at run time (the annotations themselves are checked by Clang in
// scripts/check-thread-safety.sh).
#include "service/base/annotated_mutex.h"

#include <gtest/gtest.h>

#include <thread>

namespace deform::service {
namespace {

TEST(AnnotatedMutexTest, MutexLockExcludesOtherThreadsAndCanBeReleasedEarly) {
  Mutex mutex;
  int value = 0;
  MutexLock lock(&mutex);
  std::thread writer([&] {
    MutexLock writer_lock(&mutex);
    value = 2;
  });
  value = 1;
  lock.Unlock();  // the writer may run now
  writer.join();
  lock.Lock();
  EXPECT_EQ(value, 2);
}

TEST(AnnotatedMutexTest, CondVarWaitReleasesTheMutexUntilNotified) {
  Mutex mutex;
  CondVar changed;
  bool ready = false;
  std::thread setter([&] {
    MutexLock lock(&mutex);  // only possible while the waiter is blocked in Wait()
    ready = true;
    changed.NotifyAll();
  });
  {
    MutexLock lock(&mutex);
    while (!ready) changed.Wait(&mutex);
    EXPECT_TRUE(ready);
  }
  setter.join();
}

}  // namespace
}  // namespace deform::service
