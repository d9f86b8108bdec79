// Captures what spdlog's default logger and the "audit" logger write while it lives, one line
// each "<message>" (the pattern "<%v>"), for tests of what reaches the log.
#pragma once

#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace deform::test_support {

class LogCapture {
 public:
  LogCapture() : sink_(std::make_shared<Sink>()) {
    sink_->set_pattern("<%v>");
    loggers_ = {spdlog::default_logger(), spdlog::get("audit")};
    for (const auto& logger : loggers_) {
      if (logger != nullptr) logger->sinks().push_back(sink_);
    }
  }
  ~LogCapture() { Stop(); }
  // Whether a line holding `needle` was written within `timeout`: for a line the server writes
  // after the client has its answer (a stream's "closed" line is written once its call is done).
  bool WaitFor(const std::string& needle, std::chrono::milliseconds timeout) {
    return sink_->WaitFor(needle, timeout);
  }
  std::string Stop() {
    for (const auto& logger : loggers_) {
      if (logger == nullptr) continue;
      logger->flush();
      auto& sinks = logger->sinks();
      if (!sinks.empty() && sinks.back() == sink_) sinks.pop_back();
    }
    loggers_.clear();
    return sink_->Text();
  }

 private:
  // The lines in a string, under the sink's own mutex, and a wait for one of them.
  class Sink : public spdlog::sinks::base_sink<std::mutex> {
   public:
    std::string Text() {
      std::lock_guard<std::mutex> lock(mutex_);
      return text_;
    }
    bool WaitFor(const std::string& needle, std::chrono::milliseconds timeout) {
      std::unique_lock<std::mutex> lock(mutex_);
      return written_.wait_for(lock, timeout,
                               [&] { return text_.find(needle) != std::string::npos; });
    }

   protected:
    void sink_it_(const spdlog::details::log_msg& message) override {
      spdlog::memory_buf_t formatted;
      formatter_->format(message, formatted);
      text_.append(formatted.data(), formatted.size());
      written_.notify_all();
    }
    void flush_() override {}

   private:
    std::string text_;
    std::condition_variable written_;
  };

  std::shared_ptr<Sink> sink_;
  std::vector<std::shared_ptr<spdlog::logger>> loggers_;
};

}  // namespace deform::test_support
