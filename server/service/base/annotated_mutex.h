// A mutex that Clang's thread-safety analysis understands (libstdc++'s std::mutex carries no
// annotations): Mutex, the scoped MutexLock, and CondVar to wait on a Mutex.
//
// Mutex is a std::mutex underneath (same cost, same behaviour); only the annotations are added.
// Members it protects are declared DEFORM_GUARDED_BY(mutex_), helpers that expect it held
// DEFORM_REQUIRES(mutex_) (thread_annotations.h), and the analysis checks every access under
// Clang (scripts/check-thread-safety.sh). Under GCC the annotations compile to nothing.
//
// Thread safety: as std::mutex / std::condition_variable. Not recursive.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>

#include "service/base/thread_annotations.h"

namespace deform::service {

class DEFORM_CAPABILITY("mutex") Mutex {
 public:
  Mutex() = default;
  Mutex(const Mutex&) = delete;
  Mutex& operator=(const Mutex&) = delete;

  void Lock() DEFORM_ACQUIRE() { mutex_.lock(); }
  void Unlock() DEFORM_RELEASE() { mutex_.unlock(); }
  // Tells the analysis that the calling thread holds the mutex (no check at run time): for code
  // the analysis cannot follow, such as a virtual hook called back under the owner's lock.
  void AssertHeld() const DEFORM_ASSERT_CAPABILITY(this) {}

 private:
  friend class CondVar;
  std::mutex mutex_;
};

// Holds `mutex` from construction to destruction; Unlock() and Lock() let a scope give the mutex
// up for a while (the destructor unlocks only if it is held).
class DEFORM_SCOPED_CAPABILITY MutexLock {
 public:
  explicit MutexLock(Mutex* mutex) DEFORM_ACQUIRE(mutex) : mutex_(mutex) { mutex_->Lock(); }
  ~MutexLock() DEFORM_RELEASE() {
    if (locked_) mutex_->Unlock();
  }
  MutexLock(const MutexLock&) = delete;
  MutexLock& operator=(const MutexLock&) = delete;

  void Unlock() DEFORM_RELEASE() {
    mutex_->Unlock();
    locked_ = false;
  }
  void Lock() DEFORM_ACQUIRE() {
    mutex_->Lock();
    locked_ = true;
  }

 private:
  Mutex* const mutex_;
  bool locked_ = true;
};

// A condition variable for Mutex. Wait() releases `mutex` while blocked and holds it again when it
// returns (spurious wake-ups possible: wait in a loop on the condition).
class CondVar {
 public:
  void Wait(Mutex* mutex) DEFORM_REQUIRES(mutex) {
    std::unique_lock<std::mutex> lock(mutex->mutex_, std::adopt_lock);
    cv_.wait(lock);
    lock.release();  // still held: the caller's scope owns it
  }
  // As Wait(), returning after `timeout` at the latest.
  template <class Rep, class Period>
  void WaitFor(Mutex* mutex, std::chrono::duration<Rep, Period> timeout) DEFORM_REQUIRES(mutex) {
    std::unique_lock<std::mutex> lock(mutex->mutex_, std::adopt_lock);
    cv_.wait_for(lock, timeout);
    lock.release();
  }
  void NotifyOne() { cv_.notify_one(); }
  void NotifyAll() { cv_.notify_all(); }

 private:
  std::condition_variable cv_;
};

}  // namespace deform::service
