// The WebSocket transport under a StreamHandler (stream_transport.h): one connection, one
// streaming call. Internal to web_server.cc (Boost.Beast types); the wire format is in
// web_server.h.
//
// Every operation on the socket runs on the connection's strand: the handler's StartRead,
// StartWrite and Finish (called from gRPC-free worker threads, under the handler's lock) only post
// there, so they never block and never call back inline. One read and one write at most are in
// flight (the handler asks for one of each at a time). Reading happens only when the handler asks
// (its backpressure: a Deform stream whose notice backlog is full stops asking), at most
// `max_messages_per_second` a second; a message over `max_message_bytes` is refused by Beast before
// it is read. The session owns itself (self_) from Run() until it has called the handler's
// OnDone(): once Finish() has been written (or failed) and no read, write or wait is in flight.
#pragma once

#include <spdlog/spdlog.h>

#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "service/transport/stream_transport.h"
#include "service/transport/web_auth.h"

namespace deform::web {

// Something the server can close at shutdown.
class Abortable {
 public:
  virtual void Abort() = 0;

 protected:
  ~Abortable() = default;
};

struct WebSocketLimits {
  std::size_t max_message_bytes = 0;
  int max_messages_per_second = 0;
};

template <typename Request, typename Response>
class WebSocketSession final
    : public service::StreamTransport<Request, Response>,
      public Abortable,
      public std::enable_shared_from_this<WebSocketSession<Request, Response>> {
 public:
  using Transport = service::StreamTransport<Request, Response>;
  using MakeHandler = std::function<service::StreamHandler*(Transport*)>;
  using WsStream = boost::beast::websocket::stream<boost::beast::tcp_stream>;
  using Clock = std::chrono::steady_clock;

  // `slot` is released (destroyed) with the session: the server's connection count.
  WebSocketSession(boost::beast::tcp_stream&& stream, WebSocketLimits limits,
                   std::shared_ptr<void> slot, std::string log_context)
      : ws_(std::move(stream)),
        timer_(ws_.get_executor()),
        limits_(limits),
        slot_(std::move(slot)),
        log_context_(std::move(log_context)) {}

  // Completes the handshake of `upgrade` and then starts the call with `make_handler(this)`.
  template <typename Body, typename Allocator>
  void Run(boost::beast::http::request<Body, boost::beast::http::basic_fields<Allocator>> upgrade,
           MakeHandler make_handler) {
    namespace websocket = boost::beast::websocket;
    self_ = this->shared_from_this();
    make_handler_ = std::move(make_handler);
    boost::beast::get_lowest_layer(ws_).expires_never();  // the websocket's own timeouts
    websocket::stream_base::timeout timeout{};
    timeout.handshake_timeout = std::chrono::seconds(30);
    timeout.idle_timeout = std::chrono::seconds(60);
    timeout.keep_alive_pings = true;
    ws_.set_option(timeout);
    // No limit in Beast, whose own refusal is a bare close 1009: ReadPart refuses a message over
    // max_message_bytes with the status the stream contract promises.
    ws_.read_message_max(0);
    ws_.auto_fragment(false);
    const auto offers = upgrade[boost::beast::http::field::sec_websocket_protocol];
    const bool offered = OffersDeformSubprotocol(std::string_view(offers.data(), offers.size()));
    ws_.set_option(websocket::stream_base::decorator([offered](websocket::response_type& response) {
      response.set(boost::beast::http::field::server, "deformd");
      if (offered) {
        response.set(boost::beast::http::field::sec_websocket_protocol,
                     std::string(kWebSocketSubprotocol));
      }
    }));
    ws_.async_accept(upgrade, [self = this->shared_from_this()](boost::beast::error_code error) {
      self->OnAccept(error);
    });
  }

  // Called once with the call's final status code when it ends (the service's RPC metrics);
  // before Run().
  void set_on_finished(std::function<void(int code)> on_finished) {
    on_finished_ = std::move(on_finished);
  }

  // Transport (any thread).
  void StartRead(Request* request) override {
    boost::asio::post(ws_.get_executor(),
                      [self = this->shared_from_this(), request] { self->DoRead(request); });
  }
  void StartWrite(const Response* response) override {
    boost::asio::post(ws_.get_executor(),
                      [self = this->shared_from_this(), response] { self->DoWrite(response); });
  }
  void Finish(const grpc::Status& status) override {
    boost::asio::post(ws_.get_executor(),
                      [self = this->shared_from_this(), status] { self->DoFinish(status); });
  }

  // Abortable (any thread): closes the socket; every operation in flight fails.
  void Abort() override {
    boost::asio::post(ws_.get_executor(), [self = this->shared_from_this()] {
      boost::beast::error_code ignored;
      boost::beast::get_lowest_layer(self->ws_).socket().close(ignored);
      self->timer_.cancel();
    });
  }

 private:
  void OnAccept(boost::beast::error_code error) {
    if (error) {
      spdlog::info("{} websocket handshake failed: {}", log_context_, error.message());
      self_.reset();  // no handler was made: nothing else to end
      return;
    }
    spdlog::info("{} websocket open", log_context_);
    handler_ = make_handler_(this);  // starts reading (posted: runs after this returns)
    make_handler_ = nullptr;
  }

  void DoRead(Request* request) {
    if (finishing_) return;
    const auto now = Clock::now();
    if (now - window_start_ >= std::chrono::seconds(1)) {
      window_start_ = now;
      window_messages_ = 0;
    }
    read_in_flight_ = true;
    if (limits_.max_messages_per_second > 0 &&
        window_messages_ >= limits_.max_messages_per_second) {
      timer_.expires_at(window_start_ + std::chrono::seconds(1));
      timer_.async_wait([self = this->shared_from_this(), request](boost::beast::error_code) {
        self->read_in_flight_ = false;
        if (self->finishing_) {
          self->MaybeDone();
          return;
        }
        self->DoRead(request);
      });
      return;
    }
    ++window_messages_;
    ReadPart(request);
  }

  // Reads the next message a part at a time, so that one over max_message_bytes ends the stream
  // RESOURCE_EXHAUSTED (a status message, then a close frame) after at most max_message_bytes +
  // kReadPartBytes of it were buffered.
  static constexpr std::size_t kReadPartBytes = 64 << 10;
  void ReadPart(Request* request) {
    ws_.async_read_some(
        read_buffer_, kReadPartBytes,
        [self = this->shared_from_this(), request](boost::beast::error_code error, std::size_t) {
          if (!error && self->read_buffer_.size() > self->limits_.max_message_bytes) {
            error = boost::beast::websocket::error::message_too_big;
          }
          if (!error && !self->ws_.is_message_done()) {
            self->ReadPart(request);
            return;
          }
          self->OnRead(error, request);
        });
  }

  void OnRead(boost::beast::error_code error, Request* request) {
    read_in_flight_ = false;
    if (error) {
      if (error == boost::beast::websocket::error::message_too_big) {
        read_buffer_.consume(read_buffer_.size());
        Refuse(grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                            "a WebSocket message over the limit of " +
                                std::to_string(limits_.max_message_bytes) + " bytes"));
      } else {
        Cancel();  // the client closed or went away
      }
      MaybeDone();
      return;
    }
    const auto data = read_buffer_.data();
    if (ws_.got_text()) {
      const bool end = boost::beast::buffers_to_string(data) == "end";
      read_buffer_.consume(read_buffer_.size());
      if (!end) {
        Refuse(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                            "the only text message a client may send is \"end\""));
        MaybeDone();
        return;
      }
      handler_->OnReadDone(false);  // the half-close
      return;
    }
    const bool parsed = request->ParseFromArray(static_cast<const char*>(data.data()),
                                                static_cast<int>(data.size()));
    read_buffer_.consume(read_buffer_.size());
    if (!parsed) {
      Refuse(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          "a binary message that is not a " + Request::descriptor()->full_name()));
      MaybeDone();
      return;
    }
    handler_->OnReadDone(true);
  }

  void DoWrite(const Response* response) {
    if (finishing_) return;  // the handler writes nothing after Finish()
    write_buffer_ = response->SerializeAsString();
    ws_.binary(true);
    write_in_flight_ = true;
    ws_.async_write(boost::asio::buffer(write_buffer_),
                    [self = this->shared_from_this()](boost::beast::error_code error, std::size_t) {
                      self->write_in_flight_ = false;
                      self->handler_->OnWriteDone(!error);
                      self->MaybeDone();
                    });
  }

  void DoFinish(const grpc::Status& status) {
    if (finishing_) return;
    finishing_ = true;
    timer_.cancel();
    final_status_ = refused_.value_or(status);
    const int code = static_cast<int>(final_status_.error_code());
    spdlog::info("{} websocket call ended: {} {}", log_context_, code,
                 final_status_.ok() ? std::string("OK") : final_status_.error_message());
    if (on_finished_) on_finished_(code);
    final_text_ = "status " + std::to_string(code) + " " + final_status_.error_message();
    ws_.text(true);
    write_in_flight_ = true;
    ws_.async_write(
        boost::asio::buffer(final_text_),
        [self = this->shared_from_this(), code](boost::beast::error_code error, std::size_t) {
          if (error) {
            self->write_in_flight_ = false;
            self->finished_ = true;
            self->MaybeDone();
            return;
          }
          const auto close_code = static_cast<std::uint16_t>(code == 0 ? 1000 : 4000 + code);
          self->ws_.async_close(boost::beast::websocket::close_reason(close_code),
                                [self](boost::beast::error_code) {
                                  self->write_in_flight_ = false;
                                  self->finished_ = true;
                                  self->MaybeDone();
                                });
        });
  }

  // The transport ends the call with `status` (a malformed or oversized message): the handler is
  // cancelled, and its Finish() sends this status instead of its own.
  void Refuse(grpc::Status status) {
    spdlog::warn("{} refused: {}", log_context_, status.error_message());
    if (!refused_.has_value()) refused_ = std::move(status);
    Cancel();
  }

  void Cancel() {
    if (cancelled_ || handler_ == nullptr) return;
    cancelled_ = true;
    handler_->OnCancel();
  }

  void MaybeDone() {
    if (done_ || !finished_ || read_in_flight_ || write_in_flight_) return;
    done_ = true;
    boost::beast::error_code ignored;
    boost::beast::get_lowest_layer(ws_).socket().close(ignored);
    handler_->OnDone();  // the handler's last call; it may free itself
    handler_ = nullptr;
    self_.reset();  // may free this session once the current completion returns
  }

  WsStream ws_;
  boost::asio::steady_timer timer_;
  const WebSocketLimits limits_;
  std::shared_ptr<void> slot_;
  const std::string log_context_;
  std::function<void(int code)> on_finished_;
  std::shared_ptr<WebSocketSession> self_;
  MakeHandler make_handler_;
  service::StreamHandler* handler_ = nullptr;

  // On the strand only.
  boost::beast::flat_buffer read_buffer_;
  std::string write_buffer_;
  std::string final_text_;
  grpc::Status final_status_;
  std::optional<grpc::Status> refused_;
  Clock::time_point window_start_{};
  int window_messages_ = 0;
  bool read_in_flight_ = false;
  bool write_in_flight_ = false;
  bool finishing_ = false;
  bool finished_ = false;
  bool cancelled_ = false;
  bool done_ = false;
};

}  // namespace deform::web
