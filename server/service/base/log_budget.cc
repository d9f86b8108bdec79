#include "service/base/log_budget.h"

#include <algorithm>

namespace deform::service {

LogBudget::LogBudget(double lines_per_second, double burst)
    : lines_per_second_(lines_per_second), burst_(burst), tokens_(burst), refilled_(Clock::now()) {}

bool LogBudget::Take(Clock::time_point now, std::uint64_t* held_back) {
  MutexLock lock(&mutex_);
  if (now > refilled_) {
    const double seconds = std::chrono::duration<double>(now - refilled_).count();
    tokens_ = std::min(burst_, tokens_ + seconds * lines_per_second_);
    refilled_ = now;
  }
  if (tokens_ < 1) {
    ++held_back_;
    return false;
  }
  tokens_ -= 1;
  *held_back = held_back_;
  held_back_ = 0;
  return true;
}

std::string HeldBackNote(std::uint64_t held_back) {
  if (held_back == 0) return "";
  return " (and " + std::to_string(held_back) + " more like it, not logged)";
}

}  // namespace deform::service
