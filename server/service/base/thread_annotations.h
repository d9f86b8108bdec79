// Clang's thread-safety annotations (https://clang.llvm.org/docs/ThreadSafetyAnalysis.html) under
// our own prefix: Abseil, which gRPC's headers pull in, already defines the unprefixed names.
//
// Under Clang they become attributes that -Wthread-safety checks (scripts/check-thread-safety.sh
// builds the service that way, as errors); under every other compiler they expand to nothing.
//
// The vocabulary, as used in server/service:
//   DEFORM_GUARDED_BY(mu)        a member read or written only with `mu` held
//   DEFORM_PT_GUARDED_BY(mu)     the pointee of a pointer member, likewise
//   DEFORM_REQUIRES(mu)          a function called only with `mu` held (the *Locked helpers)
//   DEFORM_EXCLUDES(mu)          a function that takes `mu` itself (callers must not hold it)
//   DEFORM_ACQUIRE / _RELEASE    a function that locks / unlocks (Mutex, MutexLock)
//   DEFORM_ASSERT_CAPABILITY(mu) a function that tells the analysis `mu` is held
//   (Mutex::AssertHeld) DEFORM_CAPABILITY, DEFORM_SCOPED_CAPABILITY  mark the lock and the
//   scoped-lock types
#pragma once

#if defined(__clang__)
#define DEFORM_THREAD_ANNOTATION_(x) __attribute__((x))
#else
#define DEFORM_THREAD_ANNOTATION_(x)
#endif

#define DEFORM_CAPABILITY(name) DEFORM_THREAD_ANNOTATION_(capability(name))
#define DEFORM_SCOPED_CAPABILITY DEFORM_THREAD_ANNOTATION_(scoped_lockable)
#define DEFORM_GUARDED_BY(x) DEFORM_THREAD_ANNOTATION_(guarded_by(x))
#define DEFORM_PT_GUARDED_BY(x) DEFORM_THREAD_ANNOTATION_(pt_guarded_by(x))
#define DEFORM_REQUIRES(...) DEFORM_THREAD_ANNOTATION_(requires_capability(__VA_ARGS__))
#define DEFORM_EXCLUDES(...) DEFORM_THREAD_ANNOTATION_(locks_excluded(__VA_ARGS__))
#define DEFORM_ACQUIRE(...) DEFORM_THREAD_ANNOTATION_(acquire_capability(__VA_ARGS__))
#define DEFORM_RELEASE(...) DEFORM_THREAD_ANNOTATION_(release_capability(__VA_ARGS__))
#define DEFORM_ASSERT_CAPABILITY(x) DEFORM_THREAD_ANNOTATION_(assert_capability(x))
#define DEFORM_RETURN_CAPABILITY(x) DEFORM_THREAD_ANNOTATION_(lock_returned(x))
#define DEFORM_NO_THREAD_SAFETY_ANALYSIS DEFORM_THREAD_ANNOTATION_(no_thread_safety_analysis)
