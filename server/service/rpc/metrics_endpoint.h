// deformd's metrics port (--metrics ADDR): GET /metrics in Prometheus' text format over HTTP.
// civetweb (Debian's libcivetweb, the server prometheus-cpp's own exposer is built on) serves it
// on its own threads.
//
// Policy: plain HTTP only (Debian 12's civetweb crashes in its TLS code with OpenSSL 3: its HTTPS
// is not used), so on a loopback address, and on any other address only with allow_plaintext
// (deformd's --plaintext): the page holds counts, no patient data or client strings, but an
// operator's token would cross the network readable. With a token file in force
// (Authenticator::uses_tokens), a scrape must present an operator's token as "Authorization: Bearer
// <token>" (Prometheus' `authorization` scrape setting): 401 without a valid token, 403 for a
// tenant's token (the metrics are the whole server's). Any other path is 404, any other method 405.
// Requests are small and answered at once; at most a few connections are served at a time
// (kThreads), so a client cannot take more than that.
//
// Thread safety: Start and the destructor from one thread; `render` and `authenticator` are called
// on civetweb's threads, concurrently, until the destructor returns.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "core/base/status.h"
#include "service/access/identity.h"

namespace deform::service {

class MetricsEndpoint {
 public:
  using RefusalCounter = std::function<bool(std::uint64_t* held_back)>;
  // Threads serving scrapes.
  static constexpr int kThreads = 2;

  // Serves on `address` ("host:port"; port 0 picks a free one: port() tells which). `render`
  // produces the page; `authenticator` checks tokens. Both must outlive the endpoint. A refused
  // scrape (401, 403) calls `count_refusal`, which counts it and says whether its log line may be
  // written, with the lines held back before it (ServiceContext::CountRefusal); empty: every
  // refusal is logged.
  // FAILED_PRECONDITION naming the flag for a non-loopback address without `allow_plaintext`, or
  // an address that cannot be bound; INVALID_ARGUMENT for an address that is not HOST:PORT.
  static StatusOr<std::unique_ptr<MetricsEndpoint>> Start(const std::string& address,
                                                          bool allow_plaintext,
                                                          const Authenticator* authenticator,
                                                          std::function<std::string()> render,
                                                          RefusalCounter count_refusal = {});
  ~MetricsEndpoint();
  MetricsEndpoint(const MetricsEndpoint&) = delete;
  MetricsEndpoint& operator=(const MetricsEndpoint&) = delete;

  int port() const { return port_; }
  // "http://host:port/metrics".
  std::string url() const;

  struct State;  // what civetweb's callbacks see

 private:
  MetricsEndpoint() = default;
  std::unique_ptr<State> state_;
  void* context_ = nullptr;  // struct mg_context*
  int port_ = 0;
  std::string host_;
};

}  // namespace deform::service
