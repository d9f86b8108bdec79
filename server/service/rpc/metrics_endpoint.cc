#include "service/rpc/metrics_endpoint.h"

#include <civetweb.h>
#include <spdlog/spdlog.h>

#include <cstring>
#include <mutex>
#include <vector>

#include "service/base/annotated_mutex.h"
#include "service/base/listen_address.h"
#include "service/base/log_budget.h"
#include "service/base/log_text.h"
#include "service/transport/transport_security.h"

namespace deform::service {

struct MetricsEndpoint::State {
  const Authenticator* authenticator = nullptr;
  std::function<std::string()> render;
  MetricsEndpoint::RefusalCounter count_refusal;
  // Whether a refusal's line may be written, and the note on the lines held back before it.
  bool LogRefusal(std::string* note) const {
    if (!count_refusal) return true;
    std::uint64_t held_back = 0;
    if (!count_refusal(&held_back)) return false;
    *note = HeldBackNote(held_back);
    return true;
  }
  Mutex mutex;
  std::string start_error DEFORM_GUARDED_BY(mutex);  // civetweb's messages while starting
};

namespace {

void Reply(mg_connection* connection, int code, const char* reason, const std::string& body,
           const char* extra_header = "") {
  mg_printf(connection,
            "HTTP/1.1 %d %s\r\nContent-Type: text/plain; charset=utf-8\r\n"
            "Content-Length: %zu\r\nConnection: close\r\n%s\r\n",
            code, reason, body.size(), extra_header);
  mg_write(connection, body.data(), body.size());
}

int HandleMetrics(mg_connection* connection, void* data) {
  auto* state = static_cast<MetricsEndpoint::State*>(data);
  const mg_request_info* request = mg_get_request_info(connection);
  const char* method = request->request_method != nullptr ? request->request_method : "";
  const bool head = std::strcmp(method, "HEAD") == 0;
  if (!head && std::strcmp(method, "GET") != 0) {
    Reply(connection, 405, "Method Not Allowed", "only GET /metrics\n", "Allow: GET, HEAD\r\n");
    return 405;
  }
  if (state->authenticator->uses_tokens()) {
    const char* header = mg_get_header(connection, "Authorization");
    StatusOr<Identity> caller = state->authenticator->Authenticate(header != nullptr ? header : "");
    if (!caller.ok()) {
      std::string note;
      if (state->LogRefusal(&note)) {
        spdlog::warn("metrics: scrape from {} refused: {}{}", request->remote_addr,
                     caller.status().message(), note);
      }
      Reply(connection, 401, "Unauthorized", caller.status().message() + "\n",
            "WWW-Authenticate: Bearer realm=\"deformd metrics\"\r\n");
      return 401;
    }
    if (caller->role != Role::kOperator && caller->role != Role::kMetrics) {
      std::string note;
      if (state->LogRefusal(&note)) {
        spdlog::warn("metrics: scrape by tenant={} refused: not an operator or metrics token{}",
                     EscapeForLog(caller->tenant), note);
      }
      Reply(connection, 403, "Forbidden", "the metrics need a metrics or operator token\n");
      return 403;
    }
  }
  const std::string body = state->render();
  mg_printf(connection,
            "HTTP/1.1 200 OK\r\nContent-Type: text/plain; version=0.0.4; charset=utf-8\r\n"
            "Content-Length: %zu\r\nConnection: close\r\n\r\n",
            body.size());
  if (!head) mg_write(connection, body.data(), body.size());
  return 200;
}

int HandleOther(mg_connection* connection, void* /*data*/) {
  Reply(connection, 404, "Not Found", "deformd serves GET /metrics only\n");
  return 404;
}

int LogMessage(const mg_connection* connection, const char* message) {
  const mg_context* context = mg_get_context(connection);
  auto* state = static_cast<MetricsEndpoint::State*>(mg_get_user_data(context));
  if (state != nullptr) {
    MutexLock lock(&state->mutex);
    if (state->start_error.size() < 1024) state->start_error += std::string(message) + "; ";
  }
  spdlog::debug("metrics: civetweb: {}", EscapeForLog(message));
  return 1;  // handled: civetweb writes nothing itself
}

// civetweb's listening_ports entry for "host:port": IPv4 as is, "[::1]:port" as is, "localhost"
// as 127.0.0.1.
StatusOr<std::string> CivetPort(const std::string& address, std::string* host) {
  const ListenHostAndPort split = SplitListenAddress(address);
  if (!split.has_port || split.port.empty()) {
    return Status::InvalidArgument("--metrics '" + EscapeForLog(address) + "' is not HOST:PORT");
  }
  *host = std::string(split.host);
  const int port = ListenPort(split);
  if (port < 0) {
    return Status::InvalidArgument("--metrics '" + EscapeForLog(address) +
                                   "': the port is not a number from 0 to 65535");
  }
  return (*host == "localhost" ? std::string("127.0.0.1") : *host) + ":" + std::to_string(port);
}

}  // namespace

StatusOr<std::unique_ptr<MetricsEndpoint>> MetricsEndpoint::Start(
    const std::string& address, bool allow_plaintext, const Authenticator* authenticator,
    std::function<std::string()> render, RefusalCounter count_refusal) {
  if (!IsLoopbackAddress(address) && !allow_plaintext) {
    return Status::FailedPrecondition(
        "--metrics '" + EscapeForLog(address) +
        "' is not a loopback address: the metrics port serves plain HTTP only, so scrape it "
        "from this host (a local agent, or a TLS-terminating proxy), or give --plaintext to "
        "serve it unencrypted on this address");
  }
  std::unique_ptr<MetricsEndpoint> endpoint(new MetricsEndpoint());
  DEFORM_ASSIGN_OR_RETURN(std::string ports, CivetPort(address, &endpoint->host_));
  endpoint->state_ = std::make_unique<State>();
  endpoint->state_->authenticator = authenticator;
  endpoint->state_->render = std::move(render);
  endpoint->state_->count_refusal = std::move(count_refusal);

  static std::once_flag library_once;
  std::call_once(library_once, [] { mg_init_library(0); });
  const std::string threads = std::to_string(kThreads);
  const char* options[] = {
      "listening_ports", ports.c_str(),       "num_threads", threads.c_str(), "request_timeout_ms",
      "10000",           "enable_keep_alive", "no",          nullptr};
  mg_callbacks callbacks{};
  callbacks.log_message = LogMessage;
  mg_context* context = mg_start(&callbacks, endpoint->state_.get(), options);
  if (context == nullptr) {
    MutexLock lock(&endpoint->state_->mutex);
    return Status::FailedPrecondition("cannot serve metrics on '" + EscapeForLog(address) +
                                      "': " + endpoint->state_->start_error);
  }
  endpoint->context_ = context;
  mg_set_request_handler(context, "/metrics$", HandleMetrics, endpoint->state_.get());
  mg_set_request_handler(context, "/", HandleOther, nullptr);
  mg_server_port bound[4];
  const int count = mg_get_server_ports(context, 4, bound);
  endpoint->port_ = count > 0 ? bound[0].port : 0;
  spdlog::info("metrics on {}{}", endpoint->url(),
               authenticator->uses_tokens() ? " (an operator's token required)" : "");
  return endpoint;
}

MetricsEndpoint::~MetricsEndpoint() {
  if (context_ != nullptr) mg_stop(static_cast<mg_context*>(context_));
}

std::string MetricsEndpoint::url() const {
  return "http://" + host_ + ":" + std::to_string(port_) + "/metrics";
}

}  // namespace deform::service
