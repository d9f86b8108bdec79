// The one place where the core's error values become gRPC statuses.
//
// deform::StatusCode mirrors the canonical gRPC codes one to one, so the mapping keeps the code
// and the message (cut to kMaxStatusMessageBytes, request_limits.h). A status that names its
// subject also carries machine-readable details: a serialized google.rpc.Status (same code, same
// message) as the grpc::Status's error_details, holding
//   - for INVALID_ARGUMENT, a google.rpc.BadRequest with one field violation: the field's path
//     (Status::subject()) and the message;
//   - for RESOURCE_EXHAUSTED naming its limit, a google.rpc.QuotaFailure with one violation: the
//     limit's scope ("server", "tenant:NAME") and a description that begins with the option
//     that sets it ("--max-meshes: ...");
//   - for UNAVAILABLE with a retry delay (a mesh being built from a shared store), a
//     google.rpc.RetryInfo whose retry_delay is Status::retry_delay_ms().
// Any other status, or one without a subject, has no details (never an empty BadRequest).
// Thread-safe (pure functions).
#pragma once

#include <grpcpp/support/status.h>

#include <string>

#include "core/base/status.h"

namespace deform::service {

grpc::StatusCode ToGrpcCode(StatusCode code);
grpc::Status ToGrpcStatus(const Status& status);

// The serialized google.rpc.Status ToGrpcStatus attaches to `status`, or "" when it attaches
// none.
std::string ErrorDetailsOf(const Status& status);

}  // namespace deform::service
