#include "loadtest/latency_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace deform::loadtest {
namespace {

constexpr int kBucketsPerDecade = 4;
constexpr int kBarWidth = 50;

// Index of the log-spaced bucket holding `value_ms` (> 0): bucket b covers
// [10^(b / 4), 10^((b + 1) / 4)) milliseconds.
int BucketOf(double value_ms) {
  return static_cast<int>(std::floor(std::log10(value_ms) * kBucketsPerDecade));
}

double BucketLowerEdge(int bucket) {
  return std::pow(10.0, static_cast<double>(bucket) / kBucketsPerDecade);
}

}  // namespace

double PercentileOfSorted(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const double rank = std::ceil(q * static_cast<double>(sorted.size()));
  const std::size_t index = rank < 1.0 ? 0 : static_cast<std::size_t>(rank) - 1;
  return sorted[std::min(index, sorted.size() - 1)];
}

LatencySummary Summarize(std::vector<double>* samples) {
  LatencySummary summary;
  if (samples->empty()) return summary;
  std::sort(samples->begin(), samples->end());
  summary.count = samples->size();
  summary.mean =
      std::accumulate(samples->begin(), samples->end(), 0.0) / static_cast<double>(samples->size());
  summary.p50 = PercentileOfSorted(*samples, 0.50);
  summary.p90 = PercentileOfSorted(*samples, 0.90);
  summary.p99 = PercentileOfSorted(*samples, 0.99);
  summary.p999 = PercentileOfSorted(*samples, 0.999);
  summary.max = samples->back();
  return summary;
}

std::string LatencyHistogramText(const std::vector<double>& sorted) {
  if (sorted.empty()) return {};
  // Non-positive samples (clock granularity) go to the lowest non-empty bucket.
  constexpr double kFloorMs = 1e-3;
  const int first = BucketOf(std::max(sorted.front(), kFloorMs));
  const int last = BucketOf(std::max(sorted.back(), kFloorMs));
  std::vector<std::size_t> counts(static_cast<std::size_t>(last - first + 1), 0);
  for (double value : sorted) {
    ++counts[static_cast<std::size_t>(BucketOf(std::max(value, kFloorMs)) - first)];
  }
  const std::size_t largest = *std::max_element(counts.begin(), counts.end());

  std::string text;
  std::size_t cumulative = 0;
  char line[256];
  for (int b = first; b <= last; ++b) {
    const std::size_t count = counts[static_cast<std::size_t>(b - first)];
    cumulative += count;
    const double share = 100.0 * static_cast<double>(count) / static_cast<double>(sorted.size());
    const double cumulative_share =
        100.0 * static_cast<double>(cumulative) / static_cast<double>(sorted.size());
    const int bar =
        static_cast<int>(std::lround(static_cast<double>(kBarWidth) * static_cast<double>(count) /
                                     static_cast<double>(largest)));
    std::snprintf(line, sizeof(line), "  [%9.3f, %9.3f) ms %8zu %6.2f%% %7.3f%%  %s\n",
                  BucketLowerEdge(b), BucketLowerEdge(b + 1), count, share, cumulative_share,
                  std::string(static_cast<std::size_t>(bar), '#').c_str());
    text += line;
  }
  return text;
}

}  // namespace deform::loadtest
