#include "bench/arithmetic_peak.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdint>

namespace deform::bench {
namespace {

// Independent chains of acc = acc * m + a: twelve, as many as the batched passes keep in
// registers, more than the multiply-add units' latency times their number on the cores measured
// (4 cycles, 2 units: 8).
constexpr int kChains = 12;
constexpr std::int64_t kSteps = 1 << 22;

// `steps` steps of every chain, in whichever instruction set the caller is compiled for (always
// inlined into it). Returns a sum of the chains, so that none is optimized away.
template <typename Vec>
__attribute__((always_inline)) inline double RunChains(std::int64_t steps) {
  Vec acc[kChains];
  Vec m, a;
  for (int i = 0; i < static_cast<int>(sizeof(Vec) / sizeof(double)); ++i) {
    m[i] = 0.999999;
    a[i] = 1e-6;
  }
  for (int c = 0; c < kChains; ++c) acc[c] = m * (1.0 + c);
  for (std::int64_t s = 0; s < steps; ++s) {
#pragma GCC unroll 12  // the chains stay in registers
    for (int c = 0; c < kChains; ++c) acc[c] = acc[c] * m + a;
  }
  double sum = 0;
  for (int c = 0; c < kChains; ++c) {
    for (int i = 0; i < static_cast<int>(sizeof(Vec) / sizeof(double)); ++i) sum += acc[c][i];
  }
  return sum;
}

typedef double Vec2 __attribute__((vector_size(16)));
typedef double Vec4 __attribute__((vector_size(32)));
typedef double Vec8 __attribute__((vector_size(64)));

// The baseline kernel's instructions: two-double vectors (SSE2 on x86-64).
double RunTwoWide(std::int64_t steps) { return RunChains<Vec2>(steps); }
#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx2,fma"))) double RunAvx2(std::int64_t steps) {
  return RunChains<Vec4>(steps);
}
__attribute__((target("avx512f"))) double RunAvx512(std::int64_t steps) {
  return RunChains<Vec8>(steps);
}
#endif

}  // namespace

double MeasureMultiplyAddRate(SolveKernel kernel, int repeats) {
  double (*run)(std::int64_t) = RunTwoWide;
  int lanes = 2;
#if defined(__x86_64__) || defined(__i386__)
  if (kernel == SolveKernel::kAvx512) {
    run = RunAvx512;
    lanes = 8;
  } else if (kernel == SolveKernel::kAvx2Fma) {
    run = RunAvx2;
    lanes = 4;
  }
#else
  (void)kernel;  // only the baseline kernel exists here
#endif
  double best = 1e30;
  for (int r = 0; r <= repeats; ++r) {  // run 0 warms the core up
    const auto start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(run(kSteps));
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (r > 0) best = std::min(best, seconds);
  }
  return static_cast<double>(kSteps) * kChains * lanes / best;
}

}  // namespace deform::bench
