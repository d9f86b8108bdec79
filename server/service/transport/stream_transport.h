// A streaming call, independent of the transport that carries it: the stream's logic (a
// StreamHandler: the Deform stream, LoadMesh) runs unchanged over gRPC (grpc_stream_adapter.h)
// and over a WebSocket (transport/websocket_session.h).
//
// The contract is gRPC's callback reactor's, so the handlers keep gRPC's semantics:
//  - The handler asks for one request at a time (StartRead); the transport fills it and calls
//    OnReadDone(true), or OnReadDone(false) once the client has half-closed (no more requests).
//    A transport that cannot half-close (a WebSocket) reports the client's end as OnCancel().
//  - The handler starts at most one write at a time (StartWrite, through its StreamWritePump); the
//    transport calls OnWriteDone(ok) when it has ended. `ok` false: the write failed.
//  - Finish(status) ends the call (once, never while a write is in flight). OnCancel() reports a
//    call the client or the transport ended early (at most once, any time before OnDone()).
//  - OnDone() is the transport's last call into the handler: after Finish() has been called and
//    every read and write the transport started has ended. The transport never touches the
//    handler after it; the handler makes no transport call after Finish().
//
// Thread safety: the transport's callbacks may come from any of its threads, one read callback
// at a time and one write callback at a time, never inline inside StartRead/StartWrite/Finish
// (a handler may call those under its own lock). The transport's methods are thread-safe.
// grpc::Status is only the value type of the final status (its canonical codes).
#pragma once

#include <grpcpp/support/status.h>

#include "service/transport/stream_write_pump.h"

namespace deform::service {

// What the transport offers a stream. Request and Response are the RPC's protobuf messages.
template <typename Request, typename Response>
class StreamTransport : public StreamWriteSink<Response> {
 public:
  // Reads the next request into `*request` (which stays the handler's and must stay valid until
  // OnReadDone); the transport then calls OnReadDone().
  virtual void StartRead(Request* request) = 0;

 protected:
  ~StreamTransport() = default;
};

// What the transport calls: the stream's reactions.
class StreamHandler {
 public:
  virtual void OnReadDone(bool ok) = 0;
  virtual void OnWriteDone(bool ok) = 0;
  virtual void OnCancel() = 0;
  virtual void OnDone() = 0;

 protected:
  ~StreamHandler() = default;
};

}  // namespace deform::service
