// A streaming call refused before it starts (e.g. UNAUTHENTICATED): a reactor that finishes at
// once with the given status and reads nothing. gRPC's reactors accept Finish() before they are
// bound to the call (it is held until then).
#pragma once

#include <grpcpp/support/server_callback.h>

namespace deform::service {

template <typename Request, typename Response>
class RejectedBidiCall final : public grpc::ServerBidiReactor<Request, Response> {
 public:
  explicit RejectedBidiCall(grpc::Status status) { this->Finish(std::move(status)); }
  void OnDone() override { delete this; }
};

}  // namespace deform::service
