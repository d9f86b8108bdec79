#include "service/base/open_files_limit.h"

#include <sys/resource.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace deform::service {

OpenFilesLimit RaiseOpenFilesLimit() {
  OpenFilesLimit result;
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0) {
    result.error = std::string("getrlimit(RLIMIT_NOFILE): ") + std::strerror(errno);
    return result;
  }
  auto value = [](rlim_t v) {
    return v == RLIM_INFINITY ? UINT64_MAX : static_cast<std::uint64_t>(v);
  };
  result.soft_before = result.soft = value(limit.rlim_cur);
  result.hard = value(limit.rlim_max);
  const rlim_t target =
      limit.rlim_max == RLIM_INFINITY ? static_cast<rlim_t>(kMaxOpenFiles) : limit.rlim_max;
  if (limit.rlim_cur != RLIM_INFINITY && limit.rlim_cur >= target) return result;
  rlimit raised = limit;
  raised.rlim_cur = target;
  if (setrlimit(RLIMIT_NOFILE, &raised) != 0) {
    result.error = std::string("setrlimit(RLIMIT_NOFILE): ") + std::strerror(errno);
    return result;
  }
  result.soft = value(raised.rlim_cur);
  return result;
}

}  // namespace deform::service
