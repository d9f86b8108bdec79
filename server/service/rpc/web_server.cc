#include "service/rpc/web_server.h"

#include <spdlog/spdlog.h>

#include <array>
#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>
#include <vector>

#include "service/base/listen_address.h"
#include "service/base/log_budget.h"
#include "service/base/log_text.h"
#include "service/deform/deform_stream_reactor.h"
#include "service/load/load_mesh_reactor.h"
#include "service/rpc/static_files.h"
#include "service/rpc/unary_calls.h"
#include "service/transport/http_host_policy.h"
#include "service/transport/loopback_port_guard.h"
#include "service/transport/status_mapping.h"
#include "service/transport/transport_security.h"
#include "service/transport/web_auth.h"
#include "service/transport/websocket_session.h"

namespace deform::web {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = boost::beast::http;
namespace websocket = boost::beast::websocket;
using tcp = boost::asio::ip::tcp;
using Request = http::request<http::string_body>;
using Response = http::response<http::string_body>;

constexpr std::size_t kMaxHeaderBytes = 8 << 10;
// A request's line and headers must arrive within kHeaderTimeout of the connection's last
// request (so that half-open connections give their slot back in seconds), its body within
// kRequestTimeout of its headers.
constexpr auto kHeaderTimeout = std::chrono::seconds(5);
constexpr auto kRequestTimeout = std::chrono::seconds(30);
// After refusing a request that was too large, its remaining bytes are read and dropped for this
// long (at most kDrainBytes) before the connection closes, so that the client reads the status
// instead of a reset.
constexpr auto kDrainTimeout = std::chrono::seconds(2);
constexpr std::size_t kDrainBytes = std::size_t{1} << 20;

// The open connections, to count them against max_connections (in all) and
// max_connections_per_address (from one peer address), and close them at shutdown.
class Connections {
 public:
  Connections(int max, int max_per_address) : max_(max), max_per_address_(max_per_address) {}
  // Why TryAcquire refused.
  enum class Refusal { kNone, kAll, kAddress };
  // A slot for a connection from `peer`, or null (and *refused why) when max_connections are open
  // or max_connections_per_address from that address; the slot is released when the last copy
  // goes.
  std::shared_ptr<void> TryAcquire(const asio::ip::address& peer, Refusal* refused) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (open_ >= max_) {
      *refused = Refusal::kAll;
      return nullptr;
    }
    int& from_peer = per_address_[peer];
    if (from_peer >= max_per_address_) {
      if (from_peer == 0) per_address_.erase(peer);
      *refused = Refusal::kAddress;
      return nullptr;
    }
    ++from_peer;
    ++open_;
    *refused = Refusal::kNone;
    return std::make_shared<Slot>(this, peer);
  }
  int open() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return open_;
  }
  void Track(const std::shared_ptr<Abortable>& connection) {
    std::lock_guard<std::mutex> lock(tracked_mutex_);
    for (auto it = tracked_.begin(); it != tracked_.end();) {
      it = it->expired() ? tracked_.erase(it) : std::next(it);
    }
    tracked_.push_back(connection);
  }
  void AbortAll() {
    std::lock_guard<std::mutex> lock(tracked_mutex_);
    for (const auto& weak : tracked_) {
      if (auto connection = weak.lock()) connection->Abort();
    }
  }

 private:
  struct Slot {
    Slot(Connections* connections, asio::ip::address peer)
        : connections(connections), peer(std::move(peer)) {}
    ~Slot() { connections->Release(peer); }
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;
    Connections* const connections;
    const asio::ip::address peer;
  };
  void Release(const asio::ip::address& peer) {
    std::lock_guard<std::mutex> lock(mutex_);
    --open_;
    auto it = per_address_.find(peer);
    if (it != per_address_.end() && --it->second <= 0) per_address_.erase(it);
  }

  const int max_;
  const int max_per_address_;
  mutable std::mutex mutex_;  // open_ and per_address_
  int open_ = 0;
  std::map<asio::ip::address, int> per_address_;
  std::mutex tracked_mutex_;
  std::vector<std::weak_ptr<Abortable>> tracked_;
};

struct Shared {
  service::ServiceContext* context;
  WebOptions options;
  Connections connections;
  HttpHostPolicy hosts;
};

int HttpStatusFor(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK:
      return 200;
    case grpc::StatusCode::INVALID_ARGUMENT:
      return 400;
    case grpc::StatusCode::UNAUTHENTICATED:
      return 401;
    case grpc::StatusCode::PERMISSION_DENIED:
      return 403;
    case grpc::StatusCode::NOT_FOUND:
      return 404;
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      return 429;
    case grpc::StatusCode::UNAVAILABLE:
      return 503;
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return 504;
    default:
      return 500;
  }
}

// The canonical code of a core Status, as the gRPC port would send it.
grpc::StatusCode CodeOf(const Status& status);

Response MakeResponse(const Request& request, http::status status, std::string_view content_type,
                      std::string body) {
  Response response{status, request.version()};
  response.set(http::field::server, "deformd");
  response.set(http::field::content_type, std::string(content_type));
  response.set(http::field::cache_control, "no-store");
  response.set("X-Content-Type-Options", "nosniff");
  // 'wasm-unsafe-eval': the page compiles meshoptimizer's decoder (WebAssembly, served from
  // this root); no script from elsewhere and no eval of script text.
  response.set("Content-Security-Policy",
               "default-src 'self'; script-src 'self' 'wasm-unsafe-eval'; connect-src 'self'; "
               "img-src 'self' data:");
  response.keep_alive(request.keep_alive());
  response.body() = std::move(body);
  response.prepare_payload();
  return response;
}

Response ErrorResponse(const Request& request, grpc::StatusCode code, const std::string& message) {
  Response response = MakeResponse(request, static_cast<http::status>(HttpStatusFor(code)),
                                   "text/plain; charset=utf-8", message + "\n");
  response.set("Deform-Status", std::to_string(static_cast<int>(code)));
  return response;
}

std::string_view HeaderOf(const Request& request, http::field field) {
  const auto value = request[field];
  return std::string_view(value.data(), value.size());
}

// The Host must be one the port is for and the Origin, when sent, that host's own (DNS
// rebinding and pages of other origins: http_host_policy.h).
bool HostAndOriginAllowed(const Shared& shared, const Request& request) {
  const auto origin = request.find(http::field::origin);
  return shared.hosts.AllowsRequest(HeaderOf(request, http::field::host),
                                    origin == request.end()
                                        ? std::nullopt
                                        : std::optional<std::string_view>(std::string_view(
                                              origin->value().data(), origin->value().size())));
}

// `method` is the full gRPC name the call is counted under (ServiceMetrics::RpcFinished).
template <typename RequestMessage, typename ResponseMessage, typename Call>
Response UnaryCall(Shared& shared, const Request& request, std::string_view method, Call call) {
  const std::string_view authorization(request[http::field::authorization].data(),
                                       request[http::field::authorization].size());
  // Authentication before the body is parsed (an unauthenticated garbage body is 401, not 400).
  const StatusOr<service::Identity> caller =
      service::AuthenticateCall(*shared.context, authorization, method, "");
  if (!caller.ok()) {
    shared.context->metrics().RpcFinished(method, static_cast<int>(CodeOf(caller.status())));
    return ErrorResponse(request, CodeOf(caller.status()), caller.status().message());
  }
  RequestMessage message;
  if (!message.ParseFromString(request.body())) {
    shared.context->metrics().RpcFinished(method,
                                          static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT));
    return ErrorResponse(request, grpc::StatusCode::INVALID_ARGUMENT,
                         "the body is not a " + RequestMessage::descriptor()->full_name());
  }
  ResponseMessage reply;
  const Status status = call(*shared.context, authorization, message, &reply);
  shared.context->metrics().RpcFinished(method, static_cast<int>(CodeOf(status)));
  if (!status.ok()) {
    return ErrorResponse(request, CodeOf(status), service::ToGrpcStatus(status).error_message());
  }
  return MakeResponse(request, http::status::ok, "application/x-protobuf",
                      reply.SerializeAsString());
}

Response ApiCall(Shared& shared, const Request& request, std::string_view method) {
  if (request.method() != http::verb::post) {
    return ErrorResponse(request, grpc::StatusCode::INVALID_ARGUMENT, "API calls are POSTs");
  }
  if (request[http::field::content_type] != "application/x-protobuf") {
    return ErrorResponse(request, grpc::StatusCode::INVALID_ARGUMENT,
                         "API calls take Content-Type application/x-protobuf");
  }
  if (method == "ListMeshes") {
    return UnaryCall<v1::ListMeshesRequest, v1::ListMeshesResponse>(
        shared, request, "/deform.v1.DeformService/ListMeshes", service::ListMeshesCall);
  }
  if (method == "GetMeshInfo") {
    return UnaryCall<v1::GetMeshInfoRequest, v1::GetMeshInfoResponse>(
        shared, request, "/deform.v1.DeformService/GetMeshInfo", service::GetMeshInfoCall);
  }
  if (method == "UnloadMesh") {
    return UnaryCall<v1::UnloadMeshRequest, v1::UnloadMeshResponse>(
        shared, request, "/deform.v1.DeformService/UnloadMesh", service::UnloadMeshCall);
  }
  return ErrorResponse(request, grpc::StatusCode::NOT_FOUND, "no such API call");
}

Response StaticFile(Shared& shared, const Request& request) {
  if (request.method() != http::verb::get && request.method() != http::verb::head) {
    return ErrorResponse(request, grpc::StatusCode::INVALID_ARGUMENT, "only GET and HEAD here");
  }
  const std::string_view target(request.target().data(), request.target().size());
  const auto path = ResolveStaticPath(shared.options.static_root, target);
  if (!path.has_value()) return ErrorResponse(request, grpc::StatusCode::NOT_FOUND, "not found");
  std::ifstream file(*path, std::ios::binary);
  std::ostringstream content;
  content << file.rdbuf();
  if (!file) return ErrorResponse(request, grpc::StatusCode::NOT_FOUND, "not found");
  Response response =
      MakeResponse(request, http::status::ok, ContentTypeFor(*path), std::move(content).str());
  if (request.method() == http::verb::head) {
    const auto length = response.body().size();
    response.body().clear();
    response.content_length(length);
  }
  return response;
}

class HttpSession final : public Abortable, public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket&& socket, Shared* shared, std::shared_ptr<void> slot)
      : stream_(std::move(socket)), shared_(shared), slot_(std::move(slot)) {
    beast::error_code ignored;
    const auto peer = stream_.socket().remote_endpoint(ignored);
    log_context_ = "http peer=" + peer.address().to_string() + ":" + std::to_string(peer.port());
  }

  void Run() {
    asio::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->DoRead(); });
  }

  void Abort() override {
    asio::post(stream_.get_executor(), [self = shared_from_this()] {
      beast::error_code ignored;
      self->stream_.socket().close(ignored);
    });
  }

 private:
  void DoRead() {
    parser_.emplace();
    parser_->header_limit(kMaxHeaderBytes);
    parser_->body_limit(shared_->options.max_body_bytes);
    stream_.expires_after(kHeaderTimeout);
    http::async_read_header(stream_, buffer_, *parser_,
                            [self = shared_from_this()](beast::error_code error, std::size_t) {
                              self->OnHeader(error);
                            });
  }

  void OnHeader(beast::error_code error) {
    if (error || parser_->is_done()) {
      OnRead(error);
      return;
    }
    stream_.expires_after(kRequestTimeout);
    http::async_read(
        stream_, buffer_, *parser_,
        [self = shared_from_this()](beast::error_code error, std::size_t) { self->OnRead(error); });
  }

  void OnRead(beast::error_code error) {
    if (error == http::error::end_of_stream) {
      stream_.socket().shutdown(tcp::socket::shutdown_send, error);
      return;
    }
    if (error == http::error::body_limit || error == http::error::header_limit) {
      RefuseTooLarge(error == http::error::header_limit);
      return;
    }
    if (error) return;  // the connection closes when the session goes
    Request request = parser_->release();
    if (websocket::is_upgrade(request)) {
      Upgrade(std::move(request));
      return;
    }
    Respond(Handle(request));
  }

  // 403 with a body for a Host the port is not for or another origin; nullopt when allowed.
  std::optional<Response> RefuseHostOrOrigin(const Request& request) {
    if (HostAndOriginAllowed(*shared_, request)) return std::nullopt;
    std::uint64_t held_back = 0;
    if (shared_->context->CountRefusal(service::ServiceMetrics::Refusal::kHttpHostOrOrigin,
                                       &held_back)) {
      spdlog::warn(
          "{} request refused: Host '{}' Origin '{}' (not an allowed host, or another "
          "origin; --http-allowed-host){}",
          log_context_, service::EscapeForLog(HeaderOf(request, http::field::host), 64),
          service::EscapeForLog(HeaderOf(request, http::field::origin), 64),
          service::HeldBackNote(held_back));
    }
    Response response =
        ErrorResponse(request, grpc::StatusCode::PERMISSION_DENIED,
                      shared_->hosts.AllowsHost(HeaderOf(request, http::field::host))
                          ? "cross-origin request"
                          : "this port does not serve that Host name (see --http-allowed-host)");
    response.keep_alive(false);
    return response;
  }

  Response Handle(const Request& request) {
    if (auto refused = RefuseHostOrOrigin(request)) return std::move(*refused);
    const std::string_view target(request.target().data(), request.target().size());
    constexpr std::string_view kApi = "/api/";
    if (target.substr(0, kApi.size()) == kApi) {
      return ApiCall(*shared_, request, target.substr(kApi.size()));
    }
    return StaticFile(*shared_, request);
  }

  // 431 for a request line and headers over kMaxHeaderBytes, 413 for a body over
  // max_body_bytes, each with a body saying the limit; then the rest of the request is drained
  // and the connection closed.
  void RefuseTooLarge(bool header) {
    std::uint64_t held_back = 0;
    const std::string message =
        header ? "request line and headers over " + std::to_string(kMaxHeaderBytes) + " bytes"
               : "request body over " + std::to_string(shared_->options.max_body_bytes) + " bytes";
    if (shared_->context->CountRefusal(service::ServiceMetrics::Refusal::kHttpTooLarge,
                                       &held_back)) {
      spdlog::warn("{} request refused: {}{}", log_context_, message,
                   service::HeldBackNote(held_back));
    }
    Request request;  // the refused one's head may be incomplete: HTTP/1.1, closing
    request.version(11);
    request.keep_alive(false);
    Response response = ErrorResponse(request, grpc::StatusCode::RESOURCE_EXHAUSTED, message);
    response.result(header ? http::status::request_header_fields_too_large
                           : http::status::payload_too_large);
    response_ = std::make_shared<Response>(std::move(response));
    stream_.expires_after(kDrainTimeout);
    http::async_write(stream_, *response_,
                      [self = shared_from_this()](beast::error_code error, std::size_t) {
                        self->response_.reset();
                        if (error) return;
                        beast::error_code ignored;
                        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                        self->Drain(0);
                      });
  }

  // Reads and drops what the client still sends, until it closes, kDrainBytes or kDrainTimeout.
  void Drain(std::size_t drained) {
    if (drained >= kDrainBytes) return;
    stream_.async_read_some(
        asio::buffer(drain_buffer_),
        [self = shared_from_this(), drained](beast::error_code error, std::size_t bytes) {
          if (!error) self->Drain(drained + bytes);
        });
  }

  void Respond(Response response) {
    response_ = std::make_shared<Response>(std::move(response));
    http::async_write(stream_, *response_,
                      [self = shared_from_this()](beast::error_code error, std::size_t) {
                        const bool keep_alive = self->response_->keep_alive();
                        self->response_.reset();
                        if (error || !keep_alive) {
                          beast::error_code ignored;
                          self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                          return;
                        }
                        self->DoRead();
                      });
  }

  void Upgrade(Request request) {
    const std::string_view target(request.target().data(), request.target().size());
    const std::string_view path = target.substr(0, target.find('?'));
    if (auto refused = RefuseHostOrOrigin(request)) {
      Respond(std::move(*refused));
      return;
    }
    const bool deform = path == "/ws/Deform";
    if (!deform && path != "/ws/LoadMesh") {
      Respond(ErrorResponse(request, grpc::StatusCode::NOT_FOUND, "no such WebSocket endpoint"));
      return;
    }
    const std::string authorization = AuthorizationFromUpgrade(
        std::string_view(request[http::field::authorization].data(),
                         request[http::field::authorization].size()),
        std::string_view(request[http::field::sec_websocket_protocol].data(),
                         request[http::field::sec_websocket_protocol].size()));
    StatusOr<service::Identity> caller =
        service::AuthenticateCall(*shared_->context, authorization, deform ? "deform" : "load", "");
    if (!caller.ok()) {  // audited by AuthenticateCall, within its budget of lines
      Response response =
          ErrorResponse(request, CodeOf(caller.status()), caller.status().message());
      response.keep_alive(false);
      Respond(std::move(response));
      return;
    }
    const WebSocketLimits limits{shared_->options.max_message_bytes,
                                 shared_->options.max_messages_per_second};
    service::ServiceContext* context = shared_->context;
    const std::string session_log = log_context_ +
                                    " tenant=" + service::EscapeForLog(caller->tenant) +
                                    (deform ? " ws=Deform" : " ws=LoadMesh");
    if (deform) {
      auto session = std::make_shared<WebSocketSession<v1::DeformRequest, v1::DeformResponse>>(
          std::move(stream_), limits, slot_, session_log);
      shared_->connections.Track(session);
      session->set_on_finished([context](int code) {
        context->metrics().RpcFinished("/deform.v1.DeformService/Deform", code);
      });
      session->Run(std::move(request), [context, caller = *caller](service::DeformTransport* t) {
        return service::NewDeformStream(context, caller, t);
      });
    } else {
      auto session = std::make_shared<WebSocketSession<v1::LoadMeshRequest, v1::LoadMeshResponse>>(
          std::move(stream_), limits, slot_, session_log);
      shared_->connections.Track(session);
      session->set_on_finished([context](int code) {
        context->metrics().RpcFinished("/deform.v1.DeformService/LoadMesh", code);
      });
      session->Run(std::move(request), [context, caller = *caller](service::LoadMeshTransport* t) {
        return service::NewLoadMeshStream(context, caller, t);
      });
    }
  }

  beast::tcp_stream stream_;
  Shared* const shared_;
  std::shared_ptr<void> slot_;
  std::string log_context_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<Response> response_;
  std::array<char, 4096> drain_buffer_{};
};

grpc::StatusCode CodeOf(const Status& status) { return service::ToGrpcCode(status.code()); }

// "host:port" -> endpoint; "localhost" is 127.0.0.1, "[::1]" an IPv6 literal.
StatusOr<tcp::endpoint> ParseEndpoint(const std::string& address) {
  const service::ListenHostAndPort split = service::SplitListenAddress(address);
  if (!split.has_port) {
    return Status::InvalidArgument("--http '" + address + "' is not HOST:PORT");
  }
  std::string host(split.host);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  if (host == "localhost") host = "127.0.0.1";
  const int port = service::ListenPort(split);
  if (port < 0) {
    return Status::InvalidArgument("--http '" + address + "' has no valid port");
  }
  beast::error_code error;
  const auto ip = asio::ip::make_address(host.empty() ? "0.0.0.0" : host, error);
  if (error) return Status::InvalidArgument("--http '" + address + "': not an IP address");
  return tcp::endpoint(ip, static_cast<unsigned short>(port));
}

}  // namespace

struct WebServer::Impl {
  Impl(service::ServiceContext* context, WebOptions options)
      : shared{context, options,
               Connections(options.max_connections, options.max_connections_per_address),
               HttpHostPolicy(options.address, options.allowed_hosts)},
        io(options.threads),
        acceptor(asio::make_strand(io)),
        accept_pause(acceptor.get_executor()) {}

  void Accept() {
    acceptor.async_accept(asio::make_strand(io), [this](beast::error_code error,
                                                        tcp::socket socket) {
      if (error) {
        if (error == asio::error::operation_aborted || !acceptor.is_open()) return;
        // Out of descriptors or buffers, the listener stays ready: accepting again at once would
        // spin. Rest, count and log within the refusal budget, then accept again.
        std::uint64_t held_back = 0;
        if (shared.context->CountRefusal(service::ServiceMetrics::Refusal::kNoDescriptors,
                                         &held_back)) {
          spdlog::error("http accept failed: {}; accepting again shortly{}", error.message(),
                        service::HeldBackNote(held_back));
        }
        accept_pause.expires_after(std::chrono::milliseconds(100));
        accept_pause.async_wait([this](beast::error_code waited) {
          if (!waited && acceptor.is_open()) Accept();
        });
        return;
      }
      beast::error_code peer_error;
      const tcp::endpoint peer = socket.remote_endpoint(peer_error);
      Connections::Refusal refused = Connections::Refusal::kNone;
      if (peer_error) {
        // The peer already went: nothing to serve.
      } else if (auto slot = shared.connections.TryAcquire(peer.address(), &refused)) {
        auto session = std::make_shared<HttpSession>(std::move(socket), &shared, std::move(slot));
        shared.connections.Track(session);
        session->Run();
      } else {
        std::uint64_t held_back = 0;
        if (shared.context->CountRefusal(service::ServiceMetrics::Refusal::kHttpConnectionLimit,
                                         &held_back)) {
          if (refused == Connections::Refusal::kAll) {
            spdlog::warn("http connection refused: {} connections open (the limit){}",
                         shared.options.max_connections, service::HeldBackNote(held_back));
          } else {
            spdlog::warn(
                "http connection from {} refused: {} connections open from that address (the "
                "limit, --http-max-connections-per-address){}",
                peer.address().to_string(), shared.options.max_connections_per_address,
                service::HeldBackNote(held_back));
          }
        }
      }
      if (socket.is_open()) {
        beast::error_code ignored;
        socket.close(ignored);
      }
      Accept();
    });
  }

  Shared shared;
  asio::io_context io;
  tcp::acceptor acceptor;
  asio::steady_timer accept_pause;  // the rest after a failed accept
  std::vector<std::thread> threads;
  int port = 0;
  service::LoopbackPortGuard port_guard;
  bool stopped = false;
};

WebServer::WebServer(service::ServiceContext* context, WebOptions options)
    : impl_(std::make_unique<Impl>(context, std::move(options))) {}

WebServer::~WebServer() { Stop(std::chrono::milliseconds(0)); }

Status WebServer::Start() {
  const WebOptions& options = impl_->shared.options;
  if (!options.allow_plaintext && !service::IsLoopbackAddress(options.address)) {
    return Status::FailedPrecondition(
        "refusing to serve plaintext HTTP on '" + options.address +
        "': the HTTP port has no TLS; use a loopback address or ask for plaintext (--plaintext)");
  }
  std::error_code fs_error;
  if (!std::filesystem::is_directory(options.static_root, fs_error)) {
    return Status::NotFound("--http-root '" + options.static_root.string() +
                            "' is not a directory");
  }
  DEFORM_ASSIGN_OR_RETURN(const tcp::endpoint endpoint, ParseEndpoint(options.address));
  beast::error_code error;
  impl_->acceptor.open(endpoint.protocol(), error);
  if (!error) impl_->acceptor.set_option(asio::socket_base::reuse_address(true), error);
  if (!error) impl_->acceptor.bind(endpoint, error);
  if (!error) impl_->acceptor.listen(asio::socket_base::max_listen_connections, error);
  if (error) {
    return Status::FailedPrecondition("cannot listen on '" + options.address +
                                      "' (--http): " + error.message());
  }
  impl_->port = impl_->acceptor.local_endpoint().port();
  // The other loopback family's address on the same port (loopback_port_guard.h).
  auto guard = service::LoopbackPortGuard::Hold(options.address, impl_->port);
  if (!guard.ok()) {
    impl_->acceptor.close(error);
    return Status::FailedPrecondition(guard.status().message() + " (--http)");
  }
  impl_->port_guard = std::move(*guard);
  impl_->Accept();
  for (int i = 0; i < std::max(1, options.threads); ++i) {
    impl_->threads.emplace_back([this] { impl_->io.run(); });
  }
  const std::string host = endpoint.address().is_v6() ? "[" + endpoint.address().to_string() + "]"
                                                      : endpoint.address().to_string();
  spdlog::info("http listening on {}:{} (static files from {})", host, impl_->port,
               service::EscapeForLog(options.static_root.string()));
  return Status::Ok();
}

int WebServer::port() const { return impl_->port; }

void WebServer::Stop(std::chrono::milliseconds grace) {
  if (impl_->stopped || impl_->threads.empty()) {
    impl_->stopped = true;
    return;
  }
  impl_->stopped = true;
  asio::post(impl_->acceptor.get_executor(), [this] {
    beast::error_code ignored;
    impl_->acceptor.close(ignored);
    impl_->accept_pause.cancel();
  });
  const auto deadline = std::chrono::steady_clock::now() + grace;
  while (impl_->shared.connections.open() > 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // Whatever is left (an idle page, a WebSocket whose close is not answered): closed now, so that
  // every stream's handler gets its OnDone before the worker pool stops.
  impl_->shared.connections.AbortAll();
  const auto abort_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (impl_->shared.connections.open() > 0 &&
         std::chrono::steady_clock::now() < abort_deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  impl_->io.stop();
  for (std::thread& thread : impl_->threads) thread.join();
  impl_->threads.clear();
}

}  // namespace deform::web
