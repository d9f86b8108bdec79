// AtomicHistogram: Prometheus' bucket rule (a value on a bound is in that bucket), cumulative
// buckets, an exact sum, and no observation lost when threads observe at once.
#include "service/metrics/atomic_histogram.h"

#include <gtest/gtest.h>
#include <prometheus/metric_family.h>

#include <cmath>
#include <thread>
#include <vector>

namespace deform::service {
namespace {

TEST(AtomicHistogramTest, BucketsAreCumulativeAndInclusive) {
  AtomicHistogram histogram("h_seconds", "help", {0.001, 0.01, 0.1});
  histogram.Observe(0.001);  // on the first bound: in it
  histogram.Observe(0.005);
  histogram.Observe(0.5);  // over every bound: +Inf only
  histogram.Observe(-1);   // counted as 0
  const prometheus::MetricFamily family = histogram.Collect();
  EXPECT_EQ(family.name, "h_seconds");
  EXPECT_EQ(family.type, prometheus::MetricType::Histogram);
  ASSERT_EQ(family.metric.size(), 1u);
  const auto& h = family.metric[0].histogram;
  ASSERT_EQ(h.bucket.size(), 4u);
  EXPECT_EQ(h.bucket[0].cumulative_count, 2u);
  EXPECT_EQ(h.bucket[1].cumulative_count, 3u);
  EXPECT_EQ(h.bucket[2].cumulative_count, 3u);
  EXPECT_EQ(h.bucket[3].cumulative_count, 4u);
  EXPECT_TRUE(std::isinf(h.bucket[3].upper_bound));
  EXPECT_EQ(h.sample_count, 4u);
  EXPECT_DOUBLE_EQ(h.sample_sum, 0.506);
}

TEST(AtomicHistogramTest, ConcurrentObservationsAreAllCounted) {
  AtomicHistogram histogram("h_seconds", "help", {0.001, 0.01});
  constexpr int kThreads = 4;
  constexpr int kEach = 100000;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&histogram, t] {
      for (int i = 0; i < kEach; ++i) histogram.Observe(t % 2 == 0 ? 0.0005 : 0.002);
    });
  }
  for (std::thread& thread : threads) thread.join();
  const prometheus::MetricFamily family = histogram.Collect();
  const auto& h = family.metric[0].histogram;
  EXPECT_EQ(h.sample_count, static_cast<std::uint64_t>(kThreads * kEach));
  EXPECT_EQ(h.bucket[0].cumulative_count, static_cast<std::uint64_t>(kThreads / 2 * kEach));
  // 200000 x 500 us + 200000 x 2 ms, summed in whole nanoseconds: exact.
  EXPECT_DOUBLE_EQ(h.sample_sum, 200000 * 0.0005 + 200000 * 0.002);
}

}  // namespace
}  // namespace deform::service
