// The gRPC transport under a StreamWritePump: writes and finishes through a server bidi reactor.
//
// The reactor owns the sink (a member constructed with `this`) and forwards its OnWriteDone() to
// the pump. Thread safety: as the pump's hooks (called under the reactor's lock); gRPC runs the
// reactions that follow (OnWriteDone, OnDone) on its own threads, never inline in these calls.
#pragma once

#include <grpcpp/support/server_callback.h>
#include <grpcpp/support/status.h>

#include "service/stream_write_pump.h"

namespace deform::service {

template <typename Request, typename Response>
class GrpcStreamSink final : public StreamWriteSink<Response> {
 public:
  explicit GrpcStreamSink(grpc::ServerBidiReactor<Request, Response>* reactor)
      : reactor_(reactor) {}

  void StartWrite(const Response* message) override { reactor_->StartWrite(message); }
  void Finish(const grpc::Status& status) override { reactor_->Finish(status); }

 private:
  grpc::ServerBidiReactor<Request, Response>* const reactor_;
};

}  // namespace deform::service
