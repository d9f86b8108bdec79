// Counts heap allocations made through operator new in the test binary that links
// allocation_counter.cc (which replaces the global operator new/delete).
#pragma once

namespace deform::test_support {

long AllocationCount();

}  // namespace deform::test_support
