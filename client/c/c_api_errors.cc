#include "c_api_errors.h"

#include <utility>

#include "status_names.h"

namespace deform::c_api {
namespace {

thread_local std::string last_error;

}  // namespace

deform_status Fail(deform_status status, std::string message) {
  last_error = std::move(message);
  return status;
}

deform_status Succeed() {
  last_error.clear();
  return DEFORM_OK;
}

deform_status FromGrpc(const grpc::Status& status, const std::string& context) {
  if (status.ok()) return Succeed();
  std::string message = client::StatusText(status);
  if (!context.empty()) message = context + ": " + message;
  return Fail(static_cast<deform_status>(status.error_code()), std::move(message));
}

}  // namespace deform::c_api

extern "C" {

const char* deform_last_error(void) { return deform::c_api::last_error.c_str(); }

const char* deform_status_name(int status) {
  switch (status) {
    case DEFORM_NO_DATA:
      return "NO_DATA";
    case DEFORM_STREAM_ENDED:
      return "STREAM_ENDED";
    default:
      break;
  }
  if (status < 0 || status > DEFORM_UNAUTHENTICATED) return "UNKNOWN_STATUS";
  return deform::client::StatusCodeName(static_cast<grpc::StatusCode>(status));
}

}  // extern "C"
