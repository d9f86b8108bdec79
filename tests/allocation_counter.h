// Counts heap allocations made through operator new in the test binary that links
// allocation_counter.cc (which replaces the global operator new/delete), on every thread.
// Under ThreadSanitizer, whose runtime owns operator new, it counts every malloc and operator new
// made by the calling thread instead (through the sanitizer's malloc hook).
#pragma once

namespace deform::test_support {

long AllocationCount();

}  // namespace deform::test_support
