#include "core/base/status.h"

#include <array>
#include <cstddef>

namespace deform {

namespace {

// Indexed by the canonical number (gRPC's doc/statuscodes.md).
constexpr std::array<const char*, kCanonicalStatusCodes> kCanonicalNames = {
    "OK",        "CANCELLED",      "UNKNOWN",           "INVALID_ARGUMENT",   "DEADLINE_EXCEEDED",
    "NOT_FOUND", "ALREADY_EXISTS", "PERMISSION_DENIED", "RESOURCE_EXHAUSTED", "FAILED_PRECONDITION",
    "ABORTED",   "OUT_OF_RANGE",   "UNIMPLEMENTED",     "INTERNAL",           "UNAVAILABLE",
    "DATA_LOSS", "UNAUTHENTICATED"};

}  // namespace

const char* CanonicalStatusCodeName(int number) {
  if (number < 0 || number >= kCanonicalStatusCodes) return nullptr;
  return kCanonicalNames[static_cast<std::size_t>(number)];
}

const char* StatusCodeName(StatusCode code) {
  const char* name = CanonicalStatusCodeName(static_cast<int>(code));
  return name != nullptr ? name : "UNKNOWN";
}

std::string Status::ToString() const {
  if (ok()) return "OK";
  return std::string(StatusCodeName(code_)) + ": " + message_;
}

Status Status::WithContext(const std::string& context) const {
  if (ok()) return *this;
  Status status = *this;
  status.message_ = context + ": " + message_;
  return status;
}

Status Status::WithSubject(std::string subject) const {
  if (ok()) return *this;
  Status status = *this;
  status.subject_ = std::move(subject);
  return status;
}

Status Status::WithLimit(std::string scope, std::string option) const {
  if (ok()) return *this;
  Status status = *this;
  status.subject_ = std::move(scope);
  status.limit_ = std::move(option);
  return status;
}

Status Status::WithRetryDelay(int milliseconds) const {
  if (ok()) return *this;
  Status status = *this;
  status.retry_delay_ms_ = milliseconds;
  return status;
}

}  // namespace deform
