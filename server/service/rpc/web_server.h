// deformd's optional HTTP port (--http ADDR): the browser viewer's static files, the unary calls
// as HTTP POSTs and the two streaming calls as WebSockets, all over the ServiceContext the gRPC
// port uses (no second implementation of anything: the same authentication, tenancy, limits, worker
// pool, outbox and backpressure; stream_transport.h, unary_calls.h).
//
// Endpoints (paths are the API's, deform.v1.DeformService):
//  - GET/HEAD /...: a file under WebOptions::static_root (static_files.h), "/" its index.html.
//  - POST /api/ListMeshes, /api/GetMeshInfo, /api/UnloadMesh: the request message as the body
//    (Content-Type application/x-protobuf), the response message as the body of a 200; an error is
//    the mapped HTTP status (400, 401, 403, 404, 429, 503, 504, 500) with header `Deform-Status:
//    <canonical code>` and the status message as text/plain. Authorization: Bearer TOKEN.
//  - WebSocket /ws/Deform and /ws/LoadMesh: each binary message one DeformRequest / LoadMeshRequest
//    from the client and one DeformResponse / LoadMeshResponse from the server, as on the gRPC
//    stream; a text message "end" from the client is the half-close; the server's last message is
//    a text message "status <code> <message>" (the call's final status), then a close frame (1000
//    when OK, 4000 + code otherwise). The token as the subprotocol "bearer.<base64url>" beside
//    "deform.v1" (web_auth.h); with a token file an upgrade without a valid token is answered 401
//    and never upgraded.
//
// Bounds on what a client sends: connections (max_connections, HTTP and WebSocket together, and
// max_connections_per_address from one peer address, so one peer cannot take every slot; more are
// closed at once, counted and logged within the refusal lines' budget), request line and headers
// 8 KiB (431 with a body), POST body max_body_bytes (413 with a body; the rest of an oversized
// request is drained for 2 s so the client reads the status), WebSocket message max_message_bytes
// (refused once that much of it arrived, at most 64 KiB more: the stream ends RESOURCE_EXHAUSTED),
// messages per second per WebSocket (max_messages_per_second: reading pauses until the next
// second), a request's line and headers (or a handshake) must arrive within 5 s of the connection's
// last request and its body within 30 s, an idle WebSocket is pinged and closed when its peer stops
// answering (60 s). A request whose Host is not one the port is for (DNS rebinding) or from a page
// of another origin is refused with 403 and a body before it is handled (http_host_policy.h). Logs
// through spdlog, client strings escaped (log_text.h).
//
// Life cycle: Start() binds and serves on its own threads; Stop() (DeformServer's shutdown, after
// the streams were drained, before the worker pool stops) stops accepting, waits up to `grace`
// for the open connections to end, then closes them. Thread safety: Start and Stop from the owning
// thread.
#pragma once

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "service/context/service_context.h"

namespace deform::web {

struct WebOptions {
  // "host:port"; port 0: the kernel picks (port() tells which).
  std::string address = "127.0.0.1:0";
  // The directory whose files are served; nothing outside it.
  std::filesystem::path static_root;
  int max_connections = 64;
  // Of them, at most this many from one peer address. Default: 32.
  int max_connections_per_address = 32;
  std::size_t max_body_bytes = std::size_t{64} << 10;
  // Largest WebSocket message from a client (a LoadMesh chunk is the largest); default 4 MiB.
  std::size_t max_message_bytes = std::size_t{4} << 20;
  int max_messages_per_second = 2000;
  // Host names served beside the loopback names and the listen address's host
  // (--http-allowed-host; http_host_policy.h).
  std::vector<std::string> allowed_hosts;
  // Serve plaintext on a non-loopback address (there is no TLS on this port).
  bool allow_plaintext = false;
  int threads = 1;
};

class WebServer {
 public:
  WebServer(service::ServiceContext* context, WebOptions options);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  // FAILED_PRECONDITION when the address cannot be bound or plaintext is refused on a
  // non-loopback address; NOT_FOUND when the static root is not a directory.
  Status Start();
  int port() const;
  void Stop(std::chrono::milliseconds grace);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace deform::web
