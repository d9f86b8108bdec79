// Single-thread read bandwidth, the physical limit of a memory-bound solve.
#pragma once

#include <cstddef>

namespace deform::bench {

// Bytes per second read by one thread streaming through a buffer of `bytes` (best of `repeats`
// passes after a warm-up). A buffer much larger than the last-level cache measures DRAM; one the
// size of a factor measures what a solve over that factor can at best achieve.
double MeasureReadBandwidth(std::size_t bytes, int repeats = 5);

}  // namespace deform::bench
