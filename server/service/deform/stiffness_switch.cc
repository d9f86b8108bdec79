#include "service/deform/stiffness_switch.h"

#include <cassert>
#include <utility>

namespace deform::service {

void StiffnessSwitch::Reset(std::shared_ptr<const MaterialFactorization> initial) {
  *this = StiffnessSwitch();
  current_ = std::move(initial);
}

void StiffnessSwitch::RefactorStarted() {
  assert(!running_ && "one refactorization at a time");
  running_ = true;
}

void StiffnessSwitch::RefactorEnded() { running_ = false; }

std::optional<std::uint64_t> StiffnessSwitch::Wait(Update update) {
  std::optional<std::uint64_t> superseded;
  if (waiting_.has_value()) superseded = waiting_->version;
  waiting_ = std::move(update);
  return superseded;
}

std::optional<StiffnessSwitch::Update> StiffnessSwitch::TakeWaiting() {
  std::optional<Update> update = std::move(waiting_);
  waiting_.reset();
  return update;
}

std::optional<std::uint64_t> StiffnessSwitch::SetNext(
    std::shared_ptr<const MaterialFactorization> factorization, std::uint64_t version) {
  std::optional<std::uint64_t> superseded;
  if (next_ != nullptr) superseded = next_version_;
  next_ = std::move(factorization);
  next_version_ = version;
  return superseded;
}

std::uint64_t StiffnessSwitch::ApplyNext() {
  assert(next_ != nullptr && "ApplyNext without a finished factorization");
  current_ = std::move(next_);
  next_ = nullptr;
  current_version_ = next_version_;
  return current_version_;
}

}  // namespace deform::service
