// Text for gRPC statuses in the clients' one-line error messages and error counts.
#pragma once

#include <grpcpp/support/status.h>

#include <string>

namespace deform::client {

// The canonical name of a status code, e.g. "INVALID_ARGUMENT"; "UNKNOWN_CODE" for values outside
// the canonical list.
const char* StatusCodeName(grpc::StatusCode code);

// "CODE: message", or just "CODE" when the message is empty or repeats the code's name.
std::string StatusText(const grpc::Status& status);

}  // namespace deform::client
