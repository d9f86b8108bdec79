#include "service/base/log_text.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <mutex>

namespace deform::service {
namespace {

void AppendHex(unsigned char c, std::string* out) {
  char buffer[8];
  std::snprintf(buffer, sizeof buffer, "\\x%02x", c);
  *out += buffer;
}

// \n, \r, \t or \xNN for a control or non-ASCII byte; false for a printable ASCII byte.
bool AppendEscapedControl(unsigned char c, std::string* out) {
  switch (c) {
    case '\n':
      *out += "\\n";
      return true;
    case '\r':
      *out += "\\r";
      return true;
    case '\t':
      *out += "\\t";
      return true;
    default:
      if (c < 0x20 || c >= 0x7f) {
        AppendHex(c, out);
        return true;
      }
      return false;
  }
}

bool NeedsEscape(std::string_view text) {
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c >= 0x7f) return true;
  }
  return false;
}

}  // namespace

std::string EscapeForLog(std::string_view text, std::size_t max_bytes) {
  std::string out;
  const std::size_t shown = text.size() < max_bytes ? text.size() : max_bytes;
  out.reserve(shown + 8);
  for (std::size_t i = 0; i < shown; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c == '\\' || c == '\'' || c == '"') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (!AppendEscapedControl(c, &out)) {
      out += static_cast<char>(c);
    }
  }
  if (shown < text.size()) out += "...";
  return out;
}

std::string EscapeControlBytes(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 8);
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (!AppendEscapedControl(c, &out)) out += ch;
  }
  return out;
}

void EscapingLogger::sink_it_(const spdlog::details::log_msg& msg) {
  const std::string_view payload(msg.payload.data(), msg.payload.size());
  if (!NeedsEscape(payload)) {
    spdlog::logger::sink_it_(msg);
    return;
  }
  const std::string escaped = EscapeControlBytes(payload);
  spdlog::details::log_msg copy = msg;
  copy.payload = spdlog::string_view_t(escaped.data(), escaped.size());
  spdlog::logger::sink_it_(copy);
}

void InstallEscapingDefaultLogger() {
  static std::once_flag once;
  std::call_once(once, [] {
    const std::shared_ptr<spdlog::logger> current = spdlog::default_logger();
    if (dynamic_cast<EscapingLogger*>(current.get()) != nullptr) return;
    auto escaping = std::make_shared<EscapingLogger>(current->name(), current->sinks().begin(),
                                                     current->sinks().end());
    escaping->set_level(current->level());
    escaping->flush_on(current->flush_level());
    spdlog::set_default_logger(escaping);
  });
}

std::shared_ptr<spdlog::logger> NewEscapingStdoutLogger(const std::string& name) {
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  if (std::shared_ptr<spdlog::logger> existing = spdlog::get(name)) return existing;
  auto sink = std::make_shared<spdlog::sinks::stdout_color_sink_mt>();
  auto logger = std::make_shared<EscapingLogger>(name, spdlog::sinks_init_list{sink});
  spdlog::register_logger(logger);
  return logger;
}

}  // namespace deform::service
