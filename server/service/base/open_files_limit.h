// The process's limit on open descriptors (RLIMIT_NOFILE): every connection takes one at its
// accept, so a server left at the common soft limit of 1,024 stops accepting (EMFILE) long before
// its hard limit. deformd raises the soft limit to the hard one at start.
#pragma once

#include <cstdint>
#include <string>

namespace deform::service {

struct OpenFilesLimit {
  std::uint64_t soft_before = 0;
  std::uint64_t soft = 0;  // now
  std::uint64_t hard = 0;  // RLIM_INFINITY reads as UINT64_MAX
  std::string error;       // why the soft limit could not be read or raised; empty when it was
};

// Raises the soft limit on open descriptors to the hard limit (capped at kMaxOpenFiles, which a
// hard limit of "unlimited" would otherwise give) and reports what it found and set.
OpenFilesLimit RaiseOpenFilesLimit();
inline constexpr std::uint64_t kMaxOpenFiles = 1 << 20;

}  // namespace deform::service
