#include "service/workers/cpu_budget.h"

#include <sched.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <thread>
#include <vector>

namespace deform::service {
namespace {

std::string_view Trim(std::string_view text) {
  const std::size_t start = text.find_first_not_of(" \t\r\n");
  if (start == std::string_view::npos) return {};
  const std::size_t end = text.find_last_not_of(" \t\r\n");
  return text.substr(start, end - start + 1);
}

// A positive integer, the whole of `text`.
std::optional<double> Positive(std::string_view text) {
  long long value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value <= 0) return std::nullopt;
  return static_cast<double>(value);
}

std::optional<std::string> ReadWholeFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// `path` ("/a/b") and each of its parents up to "" (the root), longest first.
std::vector<std::string> PathAndParents(std::string_view path) {
  std::vector<std::string> paths;
  std::string current(Trim(path));
  while (!current.empty() && current.back() == '/') current.pop_back();
  for (;;) {
    paths.push_back(current);
    if (current.empty()) break;
    const std::size_t slash = current.rfind('/');
    current.resize(slash == std::string::npos ? 0 : slash);
  }
  return paths;
}

void Tighten(std::optional<double> quota, std::optional<double>* tightest) {
  if (quota && (!*tightest || *quota < **tightest)) *tightest = quota;
}

}  // namespace

std::optional<double> ParseCgroupV2CpuMax(std::string_view text) {
  text = Trim(text);
  const std::size_t space = text.find(' ');
  if (space == std::string_view::npos) return std::nullopt;
  const std::optional<double> quota = Positive(text.substr(0, space));  // "max": nullopt
  const std::optional<double> period = Positive(Trim(text.substr(space + 1)));
  if (!quota || !period) return std::nullopt;
  return *quota / *period;
}

std::optional<double> ParseCgroupV1Quota(std::string_view quota, std::string_view period) {
  const std::optional<double> q = Positive(Trim(quota));  // "-1": nullopt
  const std::optional<double> p = Positive(Trim(period));
  if (!q || !p) return std::nullopt;
  return *q / *p;
}

std::optional<double> CgroupCpuQuota(std::string_view proc_self_cgroup, const FileReader& read) {
  std::optional<double> tightest;
  std::size_t at = 0;
  while (at < proc_self_cgroup.size()) {
    std::size_t end = proc_self_cgroup.find('\n', at);
    if (end == std::string_view::npos) end = proc_self_cgroup.size();
    const std::string_view line = proc_self_cgroup.substr(at, end - at);
    at = end + 1;
    // "hierarchy-ID:controller-list:cgroup-path"
    const std::size_t first = line.find(':');
    const std::size_t second = first == std::string_view::npos ? first : line.find(':', first + 1);
    if (second == std::string_view::npos) continue;
    const std::string_view id = line.substr(0, first);
    const std::string_view controllers = line.substr(first + 1, second - first - 1);
    const std::string_view path = line.substr(second + 1);
    if (id == "0" && controllers.empty()) {  // v2, the unified hierarchy
      for (const std::string& dir : PathAndParents(path)) {
        if (std::optional<std::string> text = read("/sys/fs/cgroup" + dir + "/cpu.max")) {
          Tighten(ParseCgroupV2CpuMax(*text), &tightest);
        }
      }
      continue;
    }
    bool cpu = false;  // v1: the hierarchy with the cpu controller
    for (std::size_t start = 0; start <= controllers.size();) {
      std::size_t comma = controllers.find(',', start);
      if (comma == std::string_view::npos) comma = controllers.size();
      cpu = cpu || controllers.substr(start, comma - start) == "cpu";
      start = comma + 1;
    }
    if (!cpu) continue;
    for (const char* mount : {"/sys/fs/cgroup/cpu,cpuacct", "/sys/fs/cgroup/cpu"}) {
      for (const std::string& dir : PathAndParents(path)) {
        const std::string base = mount + dir;
        const std::optional<std::string> quota = read(base + "/cpu.cfs_quota_us");
        const std::optional<std::string> period = read(base + "/cpu.cfs_period_us");
        if (quota && period) Tighten(ParseCgroupV1Quota(*quota, *period), &tightest);
      }
    }
  }
  return tightest;
}

int WorkersForCpus(int affinity_cpus, std::optional<double> quota) {
  int workers = std::max(affinity_cpus, 1);
  if (quota && *quota > 0) {
    const double rounded = std::ceil(*quota - 1e-9);  // 2.0000000001 from a division is 2
    workers = std::min(workers, static_cast<int>(std::min(rounded, 1e6)));
  }
  return std::max(workers, 1);
}

CpuBudget ReadCpuBudget() {
  CpuBudget budget;
  cpu_set_t set;
  CPU_ZERO(&set);
  budget.affinity_cpus = sched_getaffinity(0, sizeof set, &set) == 0
                             ? CPU_COUNT(&set)
                             : static_cast<int>(std::thread::hardware_concurrency());
  if (const std::optional<std::string> cgroup = ReadWholeFile("/proc/self/cgroup")) {
    budget.quota = CgroupCpuQuota(*cgroup, ReadWholeFile);
  }
  budget.workers = WorkersForCpus(budget.affinity_cpus, budget.quota);
  return budget;
}

}  // namespace deform::service
