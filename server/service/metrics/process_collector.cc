#include "service/metrics/process_collector.h"

#include <dirent.h>
#include <fcntl.h>
#include <prometheus/client_metric.h>
#include <prometheus/collectable.h>
#include <prometheus/metric_family.h>
#include <sys/resource.h>
#include <unistd.h>

#include <charconv>
#include <string>
#include <vector>

namespace deform::service {
namespace {

// The whole of a small /proc file; nullopt when it cannot be read.
std::optional<std::string> ReadProcFile(const char* path) {
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::string text;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0) {
      ::close(fd);
      return std::nullopt;
    }
    if (n == 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return text;
}

template <typename T>
bool ParseNumber(std::string_view field, T* value) {
  const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), *value);
  return error == std::errc() && end == field.data() + field.size();
}

// The entries of /proc/self/fd, less the descriptor that lists them; nullopt when unreadable.
std::optional<double> OpenDescriptors() {
  DIR* dir = ::opendir("/proc/self/fd");
  if (dir == nullptr) return std::nullopt;
  double count = 0;
  while (const dirent* entry = ::readdir(dir)) {
    if (entry->d_name[0] != '.') ++count;
  }
  ::closedir(dir);
  return count - 1;
}

prometheus::MetricFamily Family(const char* name, const char* help, prometheus::MetricType type,
                                std::optional<double> value) {
  prometheus::MetricFamily family{name, help, type, {}};
  if (value) {
    prometheus::ClientMetric metric;
    if (type == prometheus::MetricType::Counter) {
      metric.counter.value = *value;
    } else {
      metric.gauge.value = *value;
    }
    family.metric.push_back(std::move(metric));
  }
  return family;
}

class ProcessCollector : public prometheus::Collectable {
 public:
  ProcessCollector()
      : ticks_per_second_(static_cast<double>(::sysconf(_SC_CLK_TCK))),
        page_bytes_(static_cast<double>(::sysconf(_SC_PAGESIZE))) {
    // The start time does not change: read once.
    const std::optional<std::string> stat = ReadProcFile("/proc/self/stat");
    const std::optional<std::string> system = ReadProcFile("/proc/stat");
    const std::optional<ProcStat> parsed = stat ? ParseProcStat(*stat) : std::nullopt;
    const std::optional<std::uint64_t> boot = system ? ParseBootTime(*system) : std::nullopt;
    if (parsed && boot && ticks_per_second_ > 0) {
      start_time_seconds_ =
          static_cast<double>(*boot) + static_cast<double>(parsed->start_ticks) / ticks_per_second_;
    }
  }

  std::vector<prometheus::MetricFamily> Collect() const override {
    using prometheus::MetricType;
    const std::optional<std::string> text = ReadProcFile("/proc/self/stat");
    const std::optional<ProcStat> stat = text ? ParseProcStat(*text) : std::nullopt;
    std::optional<double> cpu, resident, virtual_bytes;
    if (stat && ticks_per_second_ > 0) {
      cpu = static_cast<double>(stat->utime_ticks + stat->stime_ticks) / ticks_per_second_;
      resident = static_cast<double>(stat->rss_pages) * page_bytes_;
      virtual_bytes = static_cast<double>(stat->vsize_bytes);
    }
    std::optional<double> max_fds;
    rlimit limit{};
    if (::getrlimit(RLIMIT_NOFILE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
      max_fds = static_cast<double>(limit.rlim_cur);
    }
    std::vector<prometheus::MetricFamily> families;
    families.reserve(6);
    families.push_back(Family("process_cpu_seconds_total",
                              "Total user and system CPU time spent in seconds.",
                              MetricType::Counter, cpu));
    families.push_back(Family("process_resident_memory_bytes", "Resident memory size in bytes.",
                              MetricType::Gauge, resident));
    families.push_back(Family("process_virtual_memory_bytes", "Virtual memory size in bytes.",
                              MetricType::Gauge, virtual_bytes));
    families.push_back(Family("process_open_fds", "Number of open file descriptors.",
                              MetricType::Gauge, OpenDescriptors()));
    families.push_back(Family("process_max_fds", "Maximum number of open file descriptors.",
                              MetricType::Gauge, max_fds));
    families.push_back(Family("process_start_time_seconds",
                              "Start time of the process since unix epoch in seconds.",
                              MetricType::Gauge, start_time_seconds_));
    return families;
  }

 private:
  double ticks_per_second_;
  double page_bytes_;
  std::optional<double> start_time_seconds_;
};

}  // namespace

std::optional<ProcStat> ParseProcStat(std::string_view text) {
  const std::size_t close = text.rfind(')');
  if (close == std::string_view::npos || text.find('(') > close) return std::nullopt;
  // Fields from 3 (state) on, separated by single spaces.
  std::string_view rest = text.substr(close + 1);
  ProcStat stat;
  int field = 2;
  bool ok = true;
  while (!rest.empty() && field < 24) {
    const std::size_t start = rest.find_first_not_of(" \n");
    if (start == std::string_view::npos) break;
    rest.remove_prefix(start);
    const std::size_t end = rest.find_first_of(" \n");
    const std::string_view value = rest.substr(0, end);
    rest.remove_prefix(end == std::string_view::npos ? rest.size() : end);
    ++field;
    switch (field) {
      case 14:
        ok = ok && ParseNumber(value, &stat.utime_ticks);
        break;
      case 15:
        ok = ok && ParseNumber(value, &stat.stime_ticks);
        break;
      case 22:
        ok = ok && ParseNumber(value, &stat.start_ticks);
        break;
      case 23:
        ok = ok && ParseNumber(value, &stat.vsize_bytes);
        break;
      case 24:
        ok = ok && ParseNumber(value, &stat.rss_pages);
        break;
      default:
        break;
    }
  }
  if (!ok || field < 24) return std::nullopt;
  return stat;
}

std::optional<std::uint64_t> ParseBootTime(std::string_view proc_stat) {
  constexpr std::string_view kKey = "btime ";
  std::size_t at = 0;
  while (at < proc_stat.size()) {
    std::size_t end = proc_stat.find('\n', at);
    if (end == std::string_view::npos) end = proc_stat.size();
    const std::string_view line = proc_stat.substr(at, end - at);
    if (line.substr(0, kKey.size()) == kKey) {
      std::uint64_t seconds = 0;
      if (ParseNumber(line.substr(kKey.size()), &seconds)) return seconds;
      return std::nullopt;
    }
    at = end + 1;
  }
  return std::nullopt;
}

std::unique_ptr<prometheus::Collectable> MakeProcessCollector() {
  return std::make_unique<ProcessCollector>();
}

}  // namespace deform::service
