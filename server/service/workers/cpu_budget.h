// How many CPUs this process may use, for --workers 0: the CPUs it may run on
// (sched_getaffinity: a cpuset, `taskset`, `docker run --cpuset-cpus`) and its cgroup's CPU quota
// (`docker run --cpus`, a Kubernetes CPU limit), not the host's cores.
//
// The quota is the tightest along the path from the process's cgroup (/proc/self/cgroup) to the
// root of its hierarchy: cgroup v2's cpu.max ("QUOTA PERIOD" or "max PERIOD") under
// /sys/fs/cgroup, else cgroup v1's cpu.cfs_quota_us / cpu.cfs_period_us (-1: none) under
// /sys/fs/cgroup/cpu,cpuacct or /sys/fs/cgroup/cpu. Inside a container the process's cgroup is
// usually the hierarchy's root as mounted there, so that file is read too. The workers are the
// quota rounded up (a 1.5-CPU quota runs 2 threads that share it, as Go's and the JVM's runtimes
// count it), at most the affinity's CPUs, at least 1.
//
// The parsers take file contents, so they are tested without a cgroup (tests/service/workers/
// cpu_budget_test.cc). Thread-safe (no state).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace deform::service {

// cgroup v2 cpu.max: CPUs' worth of quota, e.g. "150000 100000" -> 1.5; nullopt for "max ..." (no
// limit) or text that is not two positive numbers.
std::optional<double> ParseCgroupV2CpuMax(std::string_view text);

// cgroup v1: cpu.cfs_quota_us over cpu.cfs_period_us, e.g. "50000", "100000" -> 0.5; nullopt for a
// quota of -1 (no limit) or text that is not a positive number.
std::optional<double> ParseCgroupV1Quota(std::string_view quota, std::string_view period);

// A file's whole text; nullopt when it cannot be read.
using FileReader = std::function<std::optional<std::string>(const std::string& path)>;

// The tightest CPU quota of the cgroups `proc_self_cgroup` (/proc/self/cgroup's text) names, read
// through `read` from the standard mount points above; nullopt when none is set.
std::optional<double> CgroupCpuQuota(std::string_view proc_self_cgroup, const FileReader& read);

// Workers for `affinity_cpus` CPUs (<= 0: unknown, 1) and an optional quota.
int WorkersForCpus(int affinity_cpus, std::optional<double> quota);

struct CpuBudget {
  int affinity_cpus = 0;        // sched_getaffinity's count (hardware_concurrency if it fails)
  std::optional<double> quota;  // CPUs' worth, when a cgroup limits them
  int workers = 1;              // WorkersForCpus
};

// This process's budget, read now.
CpuBudget ReadCpuBudget();

}  // namespace deform::service
