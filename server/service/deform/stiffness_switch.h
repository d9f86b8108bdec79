// The stiffness of one Deform stream: the factorization its solves use, and the updates on their
// way to replacing it.
//
//  - current: the factorization solves use and its version (0: the model's default).
//  - running: one refactorization at a time runs in the background.
//  - waiting: at most one checked update waits behind it; a newer one replaces it (the older is
//    superseded before its refactorization started).
//  - next: a finished factorization waits until the stream switches it in between two solves
//    (ApplyNext()); a newer finished one replaces it (the older is superseded before it was
//    applied).
// Versions are the stream's own count of the updates it received; a newer update has a higher one.
//
// Thread safety: none; the stream's lock guards every call. The factorization current() points to
// is immutable: a solve may use it without the lock as long as the stream applies no other one
// during that solve.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "core/model/deformation_model.h"
#include "core/model/stiffness.h"

namespace deform::service {

class StiffnessSwitch {
 public:
  struct Update {
    Stiffness stiffness;
    std::uint64_t version = 0;
  };

  // Starts over with `initial` (the model's default factorization) as version 0.
  void Reset(std::shared_ptr<const MaterialFactorization> initial);

  const std::shared_ptr<const MaterialFactorization>& current() const { return current_; }
  std::uint64_t current_version() const { return current_version_; }

  bool refactor_running() const { return running_; }
  // The caller posts a refactorization now. Precondition: none is running.
  void RefactorStarted();
  // The running refactorization has ended, whatever its result.
  void RefactorEnded();

  // `update` waits for the running refactorization. Returns the version of the waiting update it
  // replaces, if any.
  std::optional<std::uint64_t> Wait(Update update);
  // The waiting update, if any, for the caller to start (RefactorStarted()).
  std::optional<Update> TakeWaiting();

  // A finished factorization for `version` waits to be applied. Returns the version of a finished
  // one it replaces, if any.
  std::optional<std::uint64_t> SetNext(std::shared_ptr<const MaterialFactorization> factorization,
                                       std::uint64_t version);
  bool has_next() const { return next_ != nullptr; }
  // Switches the next factorization in: it becomes current(). Returns its version.
  // Precondition: has_next(), and no solve is using current().
  std::uint64_t ApplyNext();

  // A refactorization runs or waits: a STIFFNESS notice may still come.
  bool busy() const { return running_ || waiting_.has_value(); }

 private:
  std::shared_ptr<const MaterialFactorization> current_;
  std::uint64_t current_version_ = 0;
  bool running_ = false;
  std::optional<Update> waiting_;
  std::shared_ptr<const MaterialFactorization> next_;
  std::uint64_t next_version_ = 0;
};

}  // namespace deform::service
