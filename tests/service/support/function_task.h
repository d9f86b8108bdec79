// An urgent task running a function, for tests of the worker pool and what runs on it.
#pragma once

#include <functional>
#include <utility>

#include "service/workers/worker_pool.h"

namespace deform::service {

class FunctionTask final : public FrameTask {
 public:
  explicit FunctionTask(std::function<void()> body) : body_(std::move(body)) {}
  void RunUrgent() override { body_(); }

 private:
  std::function<void()> body_;
};

}  // namespace deform::service
