// A Prometheus histogram whose Observe takes no lock and allocates nothing, for what is counted
// per frame (prometheus-cpp 1.0's Histogram::Observe locks a mutex per call).
//
// Each observation is two relaxed atomic additions: its bucket's count and the sum, kept in whole
// nanoseconds (exact; 2^64 ns is 584 years of observed time). The count is the buckets' total. A
// scrape reads the atomics one by one, so it may see an observation's bucket and not yet its sum:
// a difference of the observations in flight, gone at the next scrape.
//
// Thread safety: Observe and Collect from any thread, concurrently.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace prometheus {
struct MetricFamily;
}  // namespace prometheus

namespace deform::service {

class AtomicHistogram {
 public:
  // `bounds`: the buckets' upper bounds, ascending (+Inf is added).
  AtomicHistogram(std::string name, std::string help, std::vector<double> bounds);
  AtomicHistogram(const AtomicHistogram&) = delete;
  AtomicHistogram& operator=(const AtomicHistogram&) = delete;

  // `seconds` (negative or NaN: counted as 0).
  void Observe(double seconds);

  // The histogram as one family with one unlabelled series, cumulative buckets.
  prometheus::MetricFamily Collect() const;

 private:
  std::string name_;
  std::string help_;
  std::vector<double> bounds_;
  std::unique_ptr<std::atomic<std::uint64_t>[]> buckets_;  // bounds_.size() + 1, the last +Inf
  std::atomic<std::uint64_t> sum_nanoseconds_{0};
};

}  // namespace deform::service
