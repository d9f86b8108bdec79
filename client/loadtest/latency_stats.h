// Summaries of latency samples: percentiles and a text histogram with log-spaced buckets.
#pragma once

#include <string>
#include <vector>

namespace deform::loadtest {

struct LatencySummary {
  std::size_t count = 0;
  double mean = 0;
  double p50 = 0;
  double p90 = 0;
  double p99 = 0;
  double p999 = 0;
  double max = 0;
};

// Nearest-rank percentiles of `samples` (sorted in place). All zero for no samples.
LatencySummary Summarize(std::vector<double>* samples);

// Nearest-rank percentile (q in [0, 1]) of `sorted`, ascending; 0 for none.
double PercentileOfSorted(const std::vector<double>& sorted, double q);

// A histogram of `sorted` (ascending, milliseconds) in buckets spaced 4 per decade (edges 1, 1.78,
// 3.16, 5.62 times a power of ten), one line per bucket from the first non-empty to the last:
// "  [lo, hi) ms  count  percent  cumulative%  bar". Empty string for no samples.
std::string LatencyHistogramText(const std::vector<double>& sorted);

}  // namespace deform::loadtest
