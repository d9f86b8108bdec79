// The gRPC transport under a StreamHandler (stream_transport.h): a server bidi reactor that
// forwards gRPC's reactions to the handler and the handler's reads, writes and finish to gRPC.
//
// Ownership: gRPC holds the adapter from the service method until OnDone(), which forwards to the
// handler and then deletes the adapter. The handler owns itself (self_owning_handler.h) and keeps
// only a raw pointer to the adapter, which it uses only before Finish() (the transport contract).
// Thread safety: as grpc::ServerBidiReactor.
#pragma once

#include <grpcpp/support/server_callback.h>
#include <grpcpp/support/status.h>

#include "service/transport/stream_transport.h"

namespace deform::service {

template <typename Request, typename Response>
class GrpcStreamAdapter final : public grpc::ServerBidiReactor<Request, Response>,
                                public StreamTransport<Request, Response> {
 public:
  // A new adapter whose handler is made by `make_handler(transport)`, for returning to gRPC.
  template <typename MakeHandler>
  static grpc::ServerBidiReactor<Request, Response>* Create(MakeHandler&& make_handler) {
    auto* adapter = new GrpcStreamAdapter();
    adapter->handler_ = make_handler(static_cast<StreamTransport<Request, Response>*>(adapter));
    return adapter;
  }

  // StreamTransport.
  void StartRead(Request* request) override {
    grpc::ServerBidiReactor<Request, Response>::StartRead(request);
  }
  void StartWrite(const Response* response) override {
    grpc::ServerBidiReactor<Request, Response>::StartWrite(response);
  }
  void Finish(const grpc::Status& status) override {
    grpc::ServerBidiReactor<Request, Response>::Finish(status);
  }

  // gRPC's reactions.
  void OnReadDone(bool ok) override { handler_->OnReadDone(ok); }
  void OnWriteDone(bool ok) override { handler_->OnWriteDone(ok); }
  void OnCancel() override { handler_->OnCancel(); }
  void OnDone() override {
    handler_->OnDone();  // may free the handler
    delete this;
  }

 private:
  GrpcStreamAdapter() = default;
  StreamHandler* handler_ = nullptr;
};

}  // namespace deform::service
