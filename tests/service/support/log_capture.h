// Captures what spdlog's default logger and the "audit" logger write while it lives, one line
// each "<message>" (the pattern "<%v>"), for tests of what reaches the log.
#pragma once

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace deform::test_support {

class LogCapture {
 public:
  LogCapture() : sink_(std::make_shared<spdlog::sinks::ostream_sink_mt>(text_)) {
    sink_->set_pattern("<%v>");
    loggers_ = {spdlog::default_logger(), spdlog::get("audit")};
    for (const auto& logger : loggers_) {
      if (logger != nullptr) logger->sinks().push_back(sink_);
    }
  }
  ~LogCapture() { Stop(); }
  std::string Stop() {
    for (const auto& logger : loggers_) {
      if (logger == nullptr) continue;
      logger->flush();
      auto& sinks = logger->sinks();
      if (!sinks.empty() && sinks.back() == sink_) sinks.pop_back();
    }
    loggers_.clear();
    return text_.str();
  }

 private:
  std::ostringstream text_;
  std::shared_ptr<spdlog::sinks::ostream_sink_mt> sink_;
  std::vector<std::shared_ptr<spdlog::logger>> loggers_;
};

}  // namespace deform::test_support
