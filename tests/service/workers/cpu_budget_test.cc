// --workers 0's CPU count from given cgroup file contents (no real cgroup needed): cgroup v2's
// cpu.max, v1's cfs quota and period, the tightest along the cgroup's path, and the affinity cap.
#include "service/workers/cpu_budget.h"

#include <gtest/gtest.h>

#include <map>
#include <string>

namespace deform::service {
namespace {

TEST(CpuBudgetTest, ParsesCgroupV2CpuMax) {
  EXPECT_DOUBLE_EQ(*ParseCgroupV2CpuMax("150000 100000\n"), 1.5);
  EXPECT_DOUBLE_EQ(*ParseCgroupV2CpuMax("200000 100000"), 2.0);
  EXPECT_DOUBLE_EQ(*ParseCgroupV2CpuMax("50000 100000\n"), 0.5);
  EXPECT_FALSE(ParseCgroupV2CpuMax("max 100000\n").has_value());
  EXPECT_FALSE(ParseCgroupV2CpuMax("").has_value());
  EXPECT_FALSE(ParseCgroupV2CpuMax("150000").has_value());
  EXPECT_FALSE(ParseCgroupV2CpuMax("150000 0").has_value());
  EXPECT_FALSE(ParseCgroupV2CpuMax("-1 100000").has_value());
  EXPECT_FALSE(ParseCgroupV2CpuMax("15x000 100000").has_value());
}

TEST(CpuBudgetTest, ParsesCgroupV1Quota) {
  EXPECT_DOUBLE_EQ(*ParseCgroupV1Quota("50000\n", "100000\n"), 0.5);
  EXPECT_DOUBLE_EQ(*ParseCgroupV1Quota("300000", "100000"), 3.0);
  EXPECT_FALSE(ParseCgroupV1Quota("-1\n", "100000\n").has_value());
  EXPECT_FALSE(ParseCgroupV1Quota("50000", "0").has_value());
  EXPECT_FALSE(ParseCgroupV1Quota("", "100000").has_value());
}

// A reader over a map of paths to contents.
FileReader Files(std::map<std::string, std::string> files) {
  return [files = std::move(files)](const std::string& path) -> std::optional<std::string> {
    const auto it = files.find(path);
    if (it == files.end()) return std::nullopt;
    return it->second;
  };
}

TEST(CpuBudgetTest, ReadsTheV2QuotaOfAContainersRoot) {
  // Inside a container with its own cgroup namespace: "0::/", the limit on the mount's root.
  EXPECT_DOUBLE_EQ(
      *CgroupCpuQuota("0::/\n", Files({{"/sys/fs/cgroup/cpu.max", "150000 100000\n"}})), 1.5);
  EXPECT_FALSE(
      CgroupCpuQuota("0::/\n", Files({{"/sys/fs/cgroup/cpu.max", "max 100000\n"}})).has_value());
  EXPECT_FALSE(CgroupCpuQuota("0::/\n", Files({})).has_value());
}

TEST(CpuBudgetTest, TakesTheTightestV2QuotaAlongThePath) {
  const FileReader files =
      Files({{"/sys/fs/cgroup/kubepods.slice/cpu.max", "400000 100000\n"},
             {"/sys/fs/cgroup/kubepods.slice/pod1/cpu.max", "max 100000\n"},
             {"/sys/fs/cgroup/kubepods.slice/pod1/c1/cpu.max", "250000 100000\n"}});
  EXPECT_DOUBLE_EQ(*CgroupCpuQuota("0::/kubepods.slice/pod1/c1\n", files), 2.5);
  // A parent's quota binds a child without one.
  EXPECT_DOUBLE_EQ(*CgroupCpuQuota("0::/kubepods.slice/pod1\n", files), 4.0);
}

TEST(CpuBudgetTest, ReadsTheV1CpuController) {
  const std::string cgroup =
      "12:memory:/docker/abc\n"
      "4:cpu,cpuacct:/docker/abc\n"
      "1:name=systemd:/docker/abc\n";
  EXPECT_DOUBLE_EQ(
      *CgroupCpuQuota(
          cgroup, Files({{"/sys/fs/cgroup/cpu,cpuacct/docker/abc/cpu.cfs_quota_us", "200000\n"},
                         {"/sys/fs/cgroup/cpu,cpuacct/docker/abc/cpu.cfs_period_us", "100000\n"}})),
      2.0);
  // The container's own cgroup mounted as the hierarchy's root, under /sys/fs/cgroup/cpu.
  EXPECT_DOUBLE_EQ(
      *CgroupCpuQuota(cgroup, Files({{"/sys/fs/cgroup/cpu/cpu.cfs_quota_us", "50000"},
                                     {"/sys/fs/cgroup/cpu/cpu.cfs_period_us", "100000"}})),
      0.5);
  EXPECT_FALSE(CgroupCpuQuota(cgroup, Files({{"/sys/fs/cgroup/cpu/cpu.cfs_quota_us", "-1\n"},
                                             {"/sys/fs/cgroup/cpu/cpu.cfs_period_us", "100000"}}))
                   .has_value());
  // A memory controller's files are not the CPU's.
  EXPECT_FALSE(CgroupCpuQuota("12:memory:/docker/abc\n",
                              Files({{"/sys/fs/cgroup/cpu/cpu.cfs_quota_us", "50000"},
                                     {"/sys/fs/cgroup/cpu/cpu.cfs_period_us", "100000"}}))
                   .has_value());
}

TEST(CpuBudgetTest, WorkersAreTheQuotaRoundedUpAtMostTheAffinity) {
  EXPECT_EQ(WorkersForCpus(64, 1.5), 2);
  EXPECT_EQ(WorkersForCpus(64, 2.0), 2);
  EXPECT_EQ(WorkersForCpus(64, 0.5), 1);
  EXPECT_EQ(WorkersForCpus(4, 16.0), 4);
  EXPECT_EQ(WorkersForCpus(8, std::nullopt), 8);
  EXPECT_EQ(WorkersForCpus(0, std::nullopt), 1);
}

TEST(CpuBudgetTest, ThisProcessesBudgetIsConsistent) {
  const CpuBudget budget = ReadCpuBudget();
  EXPECT_GE(budget.affinity_cpus, 1);
  EXPECT_EQ(budget.workers, WorkersForCpus(budget.affinity_cpus, budget.quota));
  EXPECT_LE(budget.workers, budget.affinity_cpus);
}

}  // namespace
}  // namespace deform::service
