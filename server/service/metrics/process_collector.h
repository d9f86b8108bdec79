// Prometheus' standard process metrics, read from /proc at scrape time (as the Go client's process
// collector defines them):
//  - process_cpu_seconds_total: user and system CPU time (/proc/self/stat utime + stime).
//  - process_resident_memory_bytes, process_virtual_memory_bytes: rss pages times the page size,
//    vsize (/proc/self/stat).
//  - process_open_fds: entries of /proc/self/fd, less the one that reads it.
//  - process_max_fds: the soft RLIMIT_NOFILE (getrlimit).
//  - process_start_time_seconds: the process's start, Unix seconds (/proc/self/stat starttime in
//    clock ticks after /proc/stat's btime).
//
// Nothing here is labelled, so no client can add a series; a scrape reads three small files and
// holds no lock the streams take. A value that cannot be read is left out of that scrape (a
// family with no sample), never guessed.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>

namespace prometheus {
class Collectable;
}  // namespace prometheus

namespace deform::service {

// The fields of /proc/PID/stat that the metrics need (proc(5): fields 14, 15, 22, 23 and 24).
struct ProcStat {
  std::uint64_t utime_ticks = 0;
  std::uint64_t stime_ticks = 0;
  std::uint64_t start_ticks = 0;  // after boot
  std::uint64_t vsize_bytes = 0;
  std::int64_t rss_pages = 0;
};

// Parses /proc/PID/stat's one line. The command name (field 2, in parentheses) may hold spaces and
// parentheses, so fields are counted from its last ')'. nullopt for text that is not such a line.
std::optional<ProcStat> ParseProcStat(std::string_view text);

// The "btime" line of /proc/stat: the boot time, Unix seconds. nullopt without one.
std::optional<std::uint64_t> ParseBootTime(std::string_view proc_stat);

// The collector of the metrics above for this process. Its Collect() may run on any thread,
// concurrently.
std::unique_ptr<prometheus::Collectable> MakeProcessCollector();

}  // namespace deform::service
