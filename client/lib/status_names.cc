#include "status_names.h"

#include "core/base/status.h"

namespace deform::client {
namespace {

// grpc::StatusCode is numbered as the canonical codes, whose names the core's table holds
// (tests/client/status_names_test.cc checks every number against Abseil's names).
constexpr bool SameNumber(grpc::StatusCode grpc_code, StatusCode code) {
  return static_cast<int>(grpc_code) == static_cast<int>(code);
}
static_assert(SameNumber(grpc::StatusCode::OK, StatusCode::kOk));
static_assert(SameNumber(grpc::StatusCode::INVALID_ARGUMENT, StatusCode::kInvalidArgument));
static_assert(SameNumber(grpc::StatusCode::NOT_FOUND, StatusCode::kNotFound));
static_assert(SameNumber(grpc::StatusCode::RESOURCE_EXHAUSTED, StatusCode::kResourceExhausted));
static_assert(SameNumber(grpc::StatusCode::FAILED_PRECONDITION, StatusCode::kFailedPrecondition));
static_assert(SameNumber(grpc::StatusCode::OUT_OF_RANGE, StatusCode::kOutOfRange));
static_assert(SameNumber(grpc::StatusCode::INTERNAL, StatusCode::kInternal));
static_assert(SameNumber(grpc::StatusCode::UNAUTHENTICATED, StatusCode::kUnauthenticated));
static_assert(static_cast<int>(grpc::StatusCode::UNAUTHENTICATED) == kCanonicalStatusCodes - 1);

}  // namespace

const char* StatusCodeName(grpc::StatusCode code) {
  const char* name = CanonicalStatusCodeName(static_cast<int>(code));
  return name != nullptr ? name : "UNKNOWN_CODE";
}

std::string StatusText(const grpc::Status& status) {
  std::string text = StatusCodeName(status.error_code());
  if (!status.error_message().empty() && status.error_message() != text) {
    text += ": " + status.error_message();
  }
  return text;
}

}  // namespace deform::client
