#include "service/metrics/grpc_methods.h"

namespace deform::service {

const char* GrpcTypeName(GrpcType type) {
  switch (type) {
    case GrpcType::kUnary:
      return "unary";
    case GrpcType::kClientStream:
      return "client_stream";
    case GrpcType::kServerStream:
      return "server_stream";
    case GrpcType::kBidiStream:
      return "bidi_stream";
  }
  return "unary";
}

int ServedGrpcMethodIndex(std::string_view full_name) {
  if (full_name.empty() || full_name.front() != '/') return -1;
  full_name.remove_prefix(1);
  const std::size_t slash = full_name.find('/');
  if (slash == std::string_view::npos) return -1;
  const std::string_view service = full_name.substr(0, slash);
  const std::string_view method = full_name.substr(slash + 1);
  for (int i = 0; i < static_cast<int>(kServedGrpcMethods.size()); ++i) {
    if (kServedGrpcMethods[i].service == service && kServedGrpcMethods[i].method == method) {
      return i;
    }
  }
  return -1;
}

}  // namespace deform::service
