// A flag that asks a long computation (DeformationModel::Build) to stop early. The computation
// polls it between its phases and inside its long loops where that is cheap; whoever owns the
// work sets it (a client that went away, a server shutting down). No locks, no allocation.
//
// A token may have a parent (set at construction, outliving the token): it counts as cancelled
// when its parent is, so one server-wide token cancels every build at shutdown.
//
// Thread safety: Cancel() and cancelled() may be called from any thread at any time.
#pragma once

#include <atomic>
#include <string>

#include "core/base/status.h"

namespace deform {

class CancelToken {
 public:
  CancelToken() = default;
  explicit CancelToken(const CancelToken* parent) : parent_(parent) {}
  CancelToken(const CancelToken&) = delete;
  CancelToken& operator=(const CancelToken&) = delete;

  void Cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool cancelled() const {
    return cancelled_.load(std::memory_order_relaxed) ||
           (parent_ != nullptr && parent_->cancelled());
  }

 private:
  std::atomic<bool> cancelled_{false};
  const CancelToken* const parent_ = nullptr;
};

// FAILED_PRECONDITION "cancelled during <phase>" when `token` (may be null) is cancelled; OK
// otherwise. (Whoever cancelled knows why, and answers its own client accordingly.)
inline Status CheckCancelled(const CancelToken* token, const char* phase) {
  if (token == nullptr || !token->cancelled()) return Status::Ok();
  return Status::FailedPrecondition(std::string("cancelled during ") + phase);
}

}  // namespace deform
