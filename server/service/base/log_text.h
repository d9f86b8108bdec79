// Client strings in log lines: escaped and bounded, so that a name cannot forge a log line or
// flood the log.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace deform::service {

// `text` with backslash, quotes and every byte outside printable ASCII written as \n, \r, \t or
// \xNN, cut after `max_bytes` input bytes (then ending in "...").
std::string EscapeForLog(std::string_view text, std::size_t max_bytes = 256);

}  // namespace deform::service
