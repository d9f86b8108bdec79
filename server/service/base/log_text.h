// Client strings in log lines: escaped and bounded, so that a name cannot forge a log line or
// flood the log, and the one point that makes every line safe whatever a call site forgot.
//
// Two levels:
//  - EscapeForLog: a client string quoted in a line ('name'), quotes and backslashes escaped too,
//    bounded; call sites use it for the strings they name.
//  - The escaping logger (EscapingLogger, InstallEscapingDefaultLogger, NewEscapingLogger): every
//    line of deformd's loggers (the default one and the audit one) passes through
//    EscapeControlBytes before any sink sees it, so that a status message or any other text that
//    carries client bytes cannot put a newline, carriage return, ESC, BEL or other control byte in
//    the log. Sinks added later (a test's capture, a file) get the escaped line too.
#pragma once

#include <spdlog/logger.h>

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

namespace deform::service {

// `text` with backslash, quotes and every byte outside printable ASCII written as \n, \r, \t or
// \xNN, cut after `max_bytes` input bytes (then ending in "...").
std::string EscapeForLog(std::string_view text, std::size_t max_bytes = 256);

// `text` with every control byte (below 0x20, 0x7f) and every byte from 0x80 written as \n, \r,
// \t or \xNN; everything else (quotes, backslashes) unchanged, so that text EscapeForLog wrote
// passes unchanged.
std::string EscapeControlBytes(std::string_view text);

// A logger whose lines reach its sinks through EscapeControlBytes.
class EscapingLogger final : public spdlog::logger {
 public:
  EscapingLogger(std::string name, spdlog::sinks_init_list sinks)
      : spdlog::logger(std::move(name), sinks) {}
  template <typename It>
  EscapingLogger(std::string name, It begin, It end)
      : spdlog::logger(std::move(name), begin, end) {}

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override;
};

// Makes spdlog's default logger an EscapingLogger with the same name, sinks and level (once; a
// second call does nothing). deformd calls it before it logs; ServiceContext's constructor too, so
// that in-process servers log the same way.
void InstallEscapingDefaultLogger();

// A registered EscapingLogger `name` writing to stdout in colour (the audit log), or the one
// already registered under that name.
std::shared_ptr<spdlog::logger> NewEscapingStdoutLogger(const std::string& name);

}  // namespace deform::service
