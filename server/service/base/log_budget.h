// A budget of log lines for events any peer can cause at will (refused calls and connections):
// a burst of lines, then a steady rate, the rest counted and not written. The next line written
// learns how many were held back, so the log stays truthful and bounded: a peer that refuses
// itself a million times a second writes `lines_per_second` lines, not a million.
//
// Thread-safe; Take takes a mutex (refusals are not a per-frame path).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "service/base/annotated_mutex.h"

namespace deform::service {

class LogBudget {
 public:
  using Clock = std::chrono::steady_clock;

  // `burst` lines at once, refilled at `lines_per_second`.
  LogBudget(double lines_per_second, double burst);

  // Whether a line may be written now. When it may, *held_back receives how many lines were
  // refused since the last one written (then starts again from 0).
  bool Take(std::uint64_t* held_back) { return Take(Clock::now(), held_back); }
  bool Take(Clock::time_point now, std::uint64_t* held_back) DEFORM_EXCLUDES(mutex_);

 private:
  const double lines_per_second_;
  const double burst_;
  Mutex mutex_;
  double tokens_ DEFORM_GUARDED_BY(mutex_);
  Clock::time_point refilled_ DEFORM_GUARDED_BY(mutex_);
  std::uint64_t held_back_ DEFORM_GUARDED_BY(mutex_) = 0;
};

// What a written line adds about the ones held back before it: "" for none, else
// " (and N more like it, not logged)".
std::string HeldBackNote(std::uint64_t held_back);

}  // namespace deform::service
