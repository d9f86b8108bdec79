// The process_* metrics: /proc/PID/stat and /proc/stat parsed from given text, and the values a
// scrape of this very process shows (its descriptors opened and closed, its limit, its start).
#include "service/metrics/process_collector.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdlib>
#include <ctime>
#include <sstream>
#include <string>
#include <vector>

#include "service/metrics/service_metrics.h"

namespace deform::service {
namespace {

// A real line's shape (proc(5)), with a command name holding spaces and a ')'.
constexpr const char* kStat =
    "4242 (deform d) x) S 1 4242 4242 0 -1 4194560 1200 0 0 0 731 269 0 0 20 0 9 0 "
    "5000 123456789 3000 18446744073709551615 1 1 0 0 0 0 0 4096 0 0 0 0 17 1 0 0 0 0 0\n";

TEST(ProcessCollectorTest, ParsesTheFieldsAfterTheLastParenthesis) {
  const std::optional<ProcStat> stat = ParseProcStat(kStat);
  ASSERT_TRUE(stat.has_value());
  EXPECT_EQ(stat->utime_ticks, 731u);
  EXPECT_EQ(stat->stime_ticks, 269u);
  EXPECT_EQ(stat->start_ticks, 5000u);
  EXPECT_EQ(stat->vsize_bytes, 123456789u);
  EXPECT_EQ(stat->rss_pages, 3000);
}

TEST(ProcessCollectorTest, RefusesTextThatIsNoStatLine) {
  EXPECT_FALSE(ParseProcStat("").has_value());
  EXPECT_FALSE(ParseProcStat("4242 deformd S 1 2 3").has_value());      // no parentheses
  EXPECT_FALSE(ParseProcStat("4242 (deformd) S 1 2 3\n").has_value());  // too few fields
  std::string bad = kStat;
  bad.replace(bad.find(" 731 "), 5, " 7x1 ");
  EXPECT_FALSE(ParseProcStat(bad).has_value());
}

TEST(ProcessCollectorTest, ReadsTheBootTimeLine) {
  EXPECT_EQ(ParseBootTime("cpu  1 2 3\nintr 5\nbtime 1700000000\nprocesses 9\n"), 1700000000u);
  EXPECT_FALSE(ParseBootTime("cpu  1 2 3\nprocesses 9\n").has_value());
  EXPECT_FALSE(ParseBootTime("btime soon\n").has_value());
}

// The value of an unlabelled series in a scrape; -1 when absent.
double Value(const std::string& page, const std::string& name) {
  std::istringstream lines(page);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(name + " ", 0) == 0) return std::strtod(line.c_str() + name.size() + 1, nullptr);
  }
  return -1;
}

TEST(ProcessCollectorTest, AScrapeShowsThisProcess) {
  ServiceMetrics metrics;
  const std::string before = metrics.Serialize();
  std::vector<int> opened;
  for (int i = 0; i < 10; ++i) opened.push_back(::open("/dev/null", O_RDONLY | O_CLOEXEC));
  const std::string during = metrics.Serialize();
  for (int fd : opened) ::close(fd);
  ASSERT_GE(Value(before, "process_open_fds"), 3);
  EXPECT_EQ(Value(during, "process_open_fds"), Value(before, "process_open_fds") + 10);
  EXPECT_EQ(Value(metrics.Serialize(), "process_open_fds"), Value(before, "process_open_fds"));

  rlimit limit{};
  ASSERT_EQ(::getrlimit(RLIMIT_NOFILE, &limit), 0);
  EXPECT_EQ(Value(before, "process_max_fds"), static_cast<double>(limit.rlim_cur));
  // This test program has run for seconds to minutes, not more than a day, not in the future.
  const double start = Value(before, "process_start_time_seconds");
  const double now = static_cast<double>(std::time(nullptr));
  EXPECT_LE(start, now + 1);
  EXPECT_GT(start, now - 86400);
  EXPECT_GT(Value(before, "process_resident_memory_bytes"), 1 << 20);
  EXPECT_GE(Value(before, "process_virtual_memory_bytes"),
            Value(before, "process_resident_memory_bytes"));
  EXPECT_GE(Value(before, "process_cpu_seconds_total"), 0);
  EXPECT_NE(before.find("# TYPE process_cpu_seconds_total counter"), std::string::npos);
}

TEST(ProcessCollectorTest, CpuTimeGrowsWithWork) {
  ServiceMetrics metrics;
  const double before = Value(metrics.Serialize(), "process_cpu_seconds_total");
  timespec start{}, now{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &start);
  volatile double sink = 0;
  do {  // a quarter of a second of CPU, at least 25 clock ticks
    for (int i = 0; i < 100000; ++i) sink = sink + i * 0.5;
    ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  } while ((now.tv_sec - start.tv_sec) + (now.tv_nsec - start.tv_nsec) * 1e-9 < 0.25);
  EXPECT_GT(Value(metrics.Serialize(), "process_cpu_seconds_total"), before + 0.1);
}

}  // namespace
}  // namespace deform::service
