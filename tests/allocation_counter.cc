#include "tests/allocation_counter.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>

#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define DEFORM_TEST_UNDER_TSAN 1
#endif
#endif

#ifdef DEFORM_TEST_UNDER_TSAN
// ThreadSanitizer's runtime defines the global operator new and delete itself (strong symbols,
// linked whole), so a second definition here does not link. Its allocator calls the sanitizer's
// malloc hooks instead, for every malloc and every operator new; the hook counts those made by
// the thread that asks (the allocation-free paths under test run on the test's thread, while
// gRPC's own threads allocate at any moment).
#include <sanitizer/allocator_interface.h>

namespace {
thread_local long t_allocations = 0;

void CountAllocation(const volatile void*, std::size_t) { ++t_allocations; }
void IgnoreRelease(const volatile void*) {}

const int g_hooks_installed =
    __sanitizer_install_malloc_and_free_hooks(&CountAllocation, &IgnoreRelease);
}  // namespace

namespace deform::test_support {
long AllocationCount() {
  if (g_hooks_installed == 0) {  // nothing would be counted: fail loudly rather than pass
    std::fputs("allocation_counter: the sanitizer's malloc hook could not be installed\n", stderr);
    std::abort();
  }
  return t_allocations;
}
}  // namespace deform::test_support

#else
// Every form of the global operator new and delete is replaced, so that each allocation and its
// release go through the same malloc and free (a sanitizer reports a pair that does not match:
// gRPC allocates with the aligned and nothrow forms).

namespace {
std::atomic<long> g_allocations{0};

void* Allocate(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}

void* AllocateAligned(std::size_t size, std::align_val_t alignment) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  const std::size_t align = static_cast<std::size_t>(alignment);
  const std::size_t rounded = ((size == 0 ? 1 : size) + align - 1) / align * align;
  return std::aligned_alloc(align, rounded);
}
}  // namespace

namespace deform::test_support {
long AllocationCount() { return g_allocations.load(std::memory_order_relaxed); }
}  // namespace deform::test_support

void* operator new(std::size_t size) {
  if (void* p = Allocate(size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return Allocate(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return Allocate(size); }
void* operator new(std::size_t size, std::align_val_t alignment) {
  if (void* p = AllocateAligned(size, alignment)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t alignment) {
  return operator new(size, alignment);
}
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return AllocateAligned(size, alignment);
}
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return AllocateAligned(size, alignment);
}

void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
#endif  // DEFORM_TEST_UNDER_TSAN
