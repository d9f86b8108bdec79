#include "service/metrics/atomic_histogram.h"

#include <prometheus/client_metric.h>
#include <prometheus/metric_family.h>

#include <algorithm>
#include <cmath>

namespace deform::service {

AtomicHistogram::AtomicHistogram(std::string name, std::string help, std::vector<double> bounds)
    : name_(std::move(name)),
      help_(std::move(help)),
      bounds_(std::move(bounds)),
      buckets_(new std::atomic<std::uint64_t>[bounds_.size() + 1]) {
  for (std::size_t i = 0; i <= bounds_.size(); ++i) buckets_[i].store(0);
}

void AtomicHistogram::Observe(double seconds) {
  if (!(seconds > 0)) seconds = 0;  // NaN too
  // Prometheus' buckets are "less than or equal": the first bound >= the value.
  const auto bucket = static_cast<std::size_t>(
      std::lower_bound(bounds_.begin(), bounds_.end(), seconds) - bounds_.begin());
  buckets_[bucket].fetch_add(1, std::memory_order_relaxed);
  const double nanoseconds = std::min(seconds * 1e9, 1.8e19);  // below 2^64
  sum_nanoseconds_.fetch_add(static_cast<std::uint64_t>(nanoseconds + 0.5),
                             std::memory_order_relaxed);
}

prometheus::MetricFamily AtomicHistogram::Collect() const {
  prometheus::ClientMetric metric;
  std::uint64_t cumulative = 0;
  metric.histogram.bucket.reserve(bounds_.size() + 1);
  for (std::size_t i = 0; i <= bounds_.size(); ++i) {
    cumulative += buckets_[i].load(std::memory_order_relaxed);
    prometheus::ClientMetric::Bucket bucket;
    bucket.cumulative_count = cumulative;
    bucket.upper_bound = i < bounds_.size() ? bounds_[i] : INFINITY;
    metric.histogram.bucket.push_back(bucket);
  }
  metric.histogram.sample_count = cumulative;
  metric.histogram.sample_sum =
      static_cast<double>(sum_nanoseconds_.load(std::memory_order_relaxed)) * 1e-9;
  return prometheus::MetricFamily{name_, help_, prometheus::MetricType::Histogram, {metric}};
}

}  // namespace deform::service
