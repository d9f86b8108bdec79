#include "bench/memory_bandwidth.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <vector>

namespace deform::bench {

double MeasureReadBandwidth(std::size_t bytes, int repeats) {
  const std::size_t n = std::max<std::size_t>(bytes / sizeof(double), 1024) & ~std::size_t{7};
  std::vector<double> buffer(n, 1.0);
  double best = 1e30;
  for (int r = 0; r <= repeats; ++r) {  // pass 0 warms caches and pages
    const auto start = std::chrono::steady_clock::now();
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0, s4 = 0, s5 = 0, s6 = 0, s7 = 0;
    const double* p = buffer.data();
    for (std::size_t i = 0; i < n; i += 8) {
      s0 += p[i];
      s1 += p[i + 1];
      s2 += p[i + 2];
      s3 += p[i + 3];
      s4 += p[i + 4];
      s5 += p[i + 5];
      s6 += p[i + 6];
      s7 += p[i + 7];
    }
    double sum = s0 + s1 + s2 + s3 + s4 + s5 + s6 + s7;
    benchmark::DoNotOptimize(sum);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (r > 0) best = std::min(best, seconds);
  }
  return n * sizeof(double) / best;
}

}  // namespace deform::bench
