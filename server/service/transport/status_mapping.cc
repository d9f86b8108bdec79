#include "service/transport/status_mapping.h"

#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "service/base/request_limits.h"

namespace deform::service {

grpc::StatusCode ToGrpcCode(StatusCode code) {
  switch (code) {
    case StatusCode::kOk:
      return grpc::StatusCode::OK;
    case StatusCode::kInvalidArgument:
      return grpc::StatusCode::INVALID_ARGUMENT;
    case StatusCode::kNotFound:
      return grpc::StatusCode::NOT_FOUND;
    case StatusCode::kOutOfRange:
      return grpc::StatusCode::OUT_OF_RANGE;
    case StatusCode::kResourceExhausted:
      return grpc::StatusCode::RESOURCE_EXHAUSTED;
    case StatusCode::kFailedPrecondition:
      return grpc::StatusCode::FAILED_PRECONDITION;
    case StatusCode::kInternal:
      return grpc::StatusCode::INTERNAL;
    case StatusCode::kUnavailable:
      return grpc::StatusCode::UNAVAILABLE;
    case StatusCode::kUnauthenticated:
      return grpc::StatusCode::UNAUTHENTICATED;
    case StatusCode::kPermissionDenied:
      return grpc::StatusCode::PERMISSION_DENIED;
  }
  return grpc::StatusCode::UNKNOWN;
}

std::string ErrorDetailsOf(const Status& status) {
  google::rpc::Status details;
  if (status.code() == StatusCode::kInvalidArgument && !status.subject().empty()) {
    google::rpc::BadRequest bad_request;
    google::rpc::BadRequest::FieldViolation* violation = bad_request.add_field_violations();
    violation->set_field(BoundStatusMessage(status.subject()));
    violation->set_description(BoundStatusMessage(status.message()));
    details.add_details()->PackFrom(bad_request);
  } else if (status.code() == StatusCode::kResourceExhausted && !status.limit().empty()) {
    google::rpc::QuotaFailure quota_failure;
    google::rpc::QuotaFailure::Violation* violation = quota_failure.add_violations();
    violation->set_subject(status.subject().empty() ? "server" : status.subject());
    violation->set_description(BoundStatusMessage(status.limit() + ": " + status.message()));
    details.add_details()->PackFrom(quota_failure);
  } else if (status.code() == StatusCode::kUnavailable && status.retry_delay_ms() > 0) {
    google::rpc::RetryInfo retry;
    retry.mutable_retry_delay()->set_seconds(status.retry_delay_ms() / 1000);
    retry.mutable_retry_delay()->set_nanos((status.retry_delay_ms() % 1000) * 1'000'000);
    details.add_details()->PackFrom(retry);
  } else {
    return {};
  }
  details.set_code(static_cast<int>(ToGrpcCode(status.code())));
  details.set_message(BoundStatusMessage(status.message()));
  return details.SerializeAsString();
}

grpc::Status ToGrpcStatus(const Status& status) {
  if (status.ok()) return grpc::Status::OK;
  // Cut: a message repeating client strings must never overflow gRPC's metadata limit (the
  // details repeat the message once more, each part cut alike).
  return grpc::Status(ToGrpcCode(status.code()), BoundStatusMessage(status.message()),
                      ErrorDetailsOf(status));
}

}  // namespace deform::service
