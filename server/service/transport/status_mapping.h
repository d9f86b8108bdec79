// The one place where the core's error values become gRPC statuses.
//
// deform::StatusCode mirrors the canonical gRPC codes one to one, so the mapping keeps the code
// and the message (cut to kMaxStatusMessageBytes, request_limits.h). Thread-safe (pure functions).
#pragma once

#include <grpcpp/support/status.h>

#include "core/base/status.h"

namespace deform::service {

grpc::StatusCode ToGrpcCode(StatusCode code);
grpc::Status ToGrpcStatus(const Status& status);

}  // namespace deform::service
