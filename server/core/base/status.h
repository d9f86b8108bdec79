// Error values for the numerical core.
//
// Fallible calls return a Status (or a StatusOr<T>) built by the named factories below; the core
// never throws across its API and never asserts on untrusted input. The codes mirror the canonical
// gRPC codes so that the service maps them one to one (see server/service/status_mapping.h).
#pragma once

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace deform {

// Each value is its canonical gRPC code's number (gRPC's doc/statuscodes.md), so a code converts
// to a gRPC code by its number; the core uses only these nine.
enum class StatusCode {
  kOk = 0,
  kInvalidArgument = 3,     // the input (mesh, skeleton, pose, request) is malformed
  kNotFound = 5,            // a named thing (file, joint, mesh id) does not exist
  kPermissionDenied = 7,    // the caller is known but its role may not do this (the service's)
  kResourceExhausted = 8,   // a configured limit would be exceeded
  kFailedPrecondition = 9,  // the operation does not apply in the current state
  kOutOfRange = 11,         // a value lies outside its allowed range
  kInternal = 13,           // a numerical or programming failure (e.g. factorization broke down)
  kUnavailable = 14,        // not answerable now, but soon: retry (retry_delay_ms() says when)
  kUnauthenticated = 16,    // the caller presented no valid credentials (the service's token check)
};

// The canonical gRPC codes are numbered 0 (OK) to kCanonicalStatusCodes - 1 (UNAUTHENTICATED).
inline constexpr int kCanonicalStatusCodes = 17;

// The canonical name of the gRPC code numbered `number`, e.g. 3 -> "INVALID_ARGUMENT"; nullptr
// outside [0, kCanonicalStatusCodes). The one table of these names: the core's messages, the
// clients' error text and the service's metric labels all read it.
const char* CanonicalStatusCodeName(int number);

// The canonical name of `code`, e.g. "INVALID_ARGUMENT"; "UNKNOWN" for a number no canonical code
// has.
const char* StatusCodeName(StatusCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;  // OK

  static Status Ok() { return Status(); }
  static Status InvalidArgument(std::string msg) {
    return {StatusCode::kInvalidArgument, std::move(msg)};
  }
  static Status NotFound(std::string msg) { return {StatusCode::kNotFound, std::move(msg)}; }
  static Status PermissionDenied(std::string msg) {
    return {StatusCode::kPermissionDenied, std::move(msg)};
  }
  static Status OutOfRange(std::string msg) { return {StatusCode::kOutOfRange, std::move(msg)}; }
  static Status ResourceExhausted(std::string msg) {
    return {StatusCode::kResourceExhausted, std::move(msg)};
  }
  static Status Unavailable(std::string msg) { return {StatusCode::kUnavailable, std::move(msg)}; }
  static Status FailedPrecondition(std::string msg) {
    return {StatusCode::kFailedPrecondition, std::move(msg)};
  }
  static Status Internal(std::string msg) { return {StatusCode::kInternal, std::move(msg)}; }
  static Status Unauthenticated(std::string msg) {
    return {StatusCode::kUnauthenticated, std::move(msg)};
  }

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  // "INVALID_ARGUMENT: message", or "OK".
  std::string ToString() const;

  // Returns a copy with `context + ": "` prepended to the message (the code, the subject and the
  // limit are kept).
  Status WithContext(const std::string& context) const;

  // What the error is about, for the machine-readable details the service attaches
  // (service/transport/status_mapping.h); empty where the check does not know it. For
  // INVALID_ARGUMENT the path of the request field at fault ("upload.bone_surfaces[0].mesh");
  // for RESOURCE_EXHAUSTED whose limit it is ("server", or "tenant:NAME").
  const std::string& subject() const { return subject_; }
  // For RESOURCE_EXHAUSTED the option that sets the limit ("--max-meshes"); empty otherwise.
  const std::string& limit() const { return limit_; }
  // For UNAVAILABLE how long the caller should wait before retrying; 0: no hint.
  int retry_delay_ms() const { return retry_delay_ms_; }

  // Returns a copy with the subject set (an OK status is returned unchanged: it has none).
  Status WithSubject(std::string subject) const;
  // Returns a copy naming the limit that refused: its scope (the subject) and its option.
  Status WithLimit(std::string scope, std::string option) const;
  // Returns a copy advising a retry after `milliseconds` (> 0).
  Status WithRetryDelay(int milliseconds) const;

 private:
  Status(StatusCode code, std::string msg) : code_(code), message_(std::move(msg)) {}
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
  std::string subject_;
  std::string limit_;
  int retry_delay_ms_ = 0;
};

// Either a value or a non-OK Status.
template <typename T>
class [[nodiscard]] StatusOr {
 public:
  StatusOr(T value) : value_(std::move(value)) {}        // NOLINT: implicit by design
  StatusOr(Status status) : value_(std::move(status)) {  // NOLINT: implicit by design
    assert(!std::get<Status>(value_).ok() && "StatusOr built from an OK status");
  }

  bool ok() const { return std::holds_alternative<T>(value_); }
  Status status() const { return ok() ? Status::Ok() : std::get<Status>(value_); }

  // Precondition: ok().
  T& value() & { return std::get<T>(value_); }
  const T& value() const& { return std::get<T>(value_); }
  T&& value() && { return std::get<T>(std::move(value_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

 private:
  std::variant<T, Status> value_;
};

}  // namespace deform

// Returns early from the enclosing function when `expr` (a Status) is not OK.
#define DEFORM_RETURN_IF_ERROR(expr)                 \
  do {                                               \
    ::deform::Status deform_status_ = (expr);        \
    if (!deform_status_.ok()) return deform_status_; \
  } while (0)

#define DEFORM_CONCAT_INNER_(a, b) a##b
#define DEFORM_CONCAT_(a, b) DEFORM_CONCAT_INNER_(a, b)
// Declares `lhs` from a StatusOr expression, returning early with its status on error.
#define DEFORM_ASSIGN_OR_RETURN(lhs, expr) \
  DEFORM_ASSIGN_OR_RETURN_IMPL_(DEFORM_CONCAT_(deform_statusor_, __LINE__), lhs, expr)
#define DEFORM_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr) \
  auto tmp = (expr);                                  \
  if (!tmp.ok()) return tmp.status();                 \
  lhs = std::move(tmp).value()
