// A Deform stream over deformd's WebSocket transport (/ws/Deform, service/rpc/web_server.h) behind
// the client library's DeformStream interface, so that one test body runs over both transports.
//
// Wire format as web_server.h states it: each binary message one DeformRequest (from the client)
// or DeformResponse (from the server); the client's text message "end" half-closes; the server's
// last message is the text "status <code> <message>", then a close frame. Frames must carry
// float32 positions (no frame encodings here). Callbacks run on the stream's own I/O thread;
// on_done once, with the final status (CANCELLED after Cancel()).
//
// Everything on the socket runs on that one thread (Boost.Beast streams are not thread-safe):
// SendPose, SendStiffness, Close and Cancel only post there; writes go out one at a time, in order.
#pragma once

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "deform/v1/deform.pb.h"
#include "deform_client.h"

namespace deform::test_support {

class WebSocketDeformStream final : public client::DeformStream {
 public:
  // Connects to 127.0.0.1:`port`, upgrades and sends the start on `mesh_id`. A failed upgrade
  // ends the stream at once with UNAVAILABLE naming the error.
  WebSocketDeformStream(int port, const std::string& mesh_id,
                        client::DeformClient::StreamCallbacks callbacks)
      : callbacks_(std::move(callbacks)), ws_(io_) {
    v1::DeformRequest start;
    start.mutable_start()->set_mesh_id(mesh_id);
    try {
      boost::asio::ip::tcp::resolver resolver(io_);
      boost::asio::connect(ws_.next_layer(), resolver.resolve("127.0.0.1", std::to_string(port)));
      ws_.set_option(boost::beast::websocket::stream_base::decorator(
          [](boost::beast::websocket::request_type& request) {
            request.set(boost::beast::http::field::sec_websocket_protocol, "deform.v1");
          }));
      ws_.handshake("127.0.0.1:" + std::to_string(port), "/ws/Deform");
    } catch (const std::exception& error) {
      Finish(grpc::Status(grpc::StatusCode::UNAVAILABLE, error.what()));
      return;
    }
    Enqueue(/*text=*/false, start.SerializeAsString());
    ReadNext();
    thread_ = std::thread([this] { io_.run(); });
  }

  ~WebSocketDeformStream() override {
    Cancel();
    if (thread_.joinable()) thread_.join();
  }

  bool SendPose(const v1::PoseUpdate& pose) override {
    v1::DeformRequest request;
    *request.mutable_pose() = pose;
    return Send(/*text=*/false, request.SerializeAsString());
  }
  bool SendStiffness(const v1::StiffnessUpdate& stiffness) override {
    v1::DeformRequest request;
    *request.mutable_stiffness() = stiffness;
    return Send(/*text=*/false, request.SerializeAsString());
  }
  void Close() override { Send(/*text=*/true, "end"); }
  void Cancel() override {
    boost::asio::post(io_, [this] {
      if (finished_) return;
      cancelled_ = true;
      boost::system::error_code ignored;
      ws_.next_layer().shutdown(boost::asio::ip::tcp::socket::shutdown_both, ignored);
      ws_.next_layer().close(ignored);
    });
  }
  grpc::Status Wait() override {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return status_.has_value(); });
    return *status_;
  }

 private:
  // From the caller's thread: false once the stream has ended or Close() was called.
  bool Send(bool text, std::string bytes) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (closed_ || status_.has_value()) return false;
      if (text) closed_ = true;
    }
    boost::asio::post(
        io_, [this, text, bytes = std::move(bytes)]() mutable { Enqueue(text, std::move(bytes)); });
    return true;
  }

  // On the I/O thread (or before it starts).
  void Enqueue(bool text, std::string bytes) {
    if (finished_) return;
    outgoing_.emplace_back(text, std::move(bytes));
    if (outgoing_.size() == 1) WriteNext();
  }
  void WriteNext() {
    ws_.text(outgoing_.front().first);
    ws_.async_write(boost::asio::buffer(outgoing_.front().second),
                    [this](boost::system::error_code error, std::size_t) {
                      if (error) return;  // the read side reports the end
                      outgoing_.pop_front();
                      if (!outgoing_.empty()) WriteNext();
                    });
  }
  void ReadNext() {
    ws_.async_read(incoming_, [this](boost::system::error_code error, std::size_t) {
      if (error) {
        if (cancelled_) {
          Finish(grpc::Status(grpc::StatusCode::CANCELLED, "cancelled by the client"));
        } else if (final_.has_value()) {
          Finish(*final_);
        } else {
          Finish(grpc::Status(grpc::StatusCode::UNAVAILABLE,
                              "the WebSocket ended without a status: " + error.message()));
        }
        return;
      }
      const std::string message = boost::beast::buffers_to_string(incoming_.data());
      incoming_.consume(incoming_.size());
      if (ws_.got_text()) {
        final_ = ParseStatus(message);
      } else {
        v1::DeformResponse response;
        if (!response.ParseFromString(message)) {
          final_ = grpc::Status(grpc::StatusCode::INTERNAL, "an unparsable DeformResponse");
        } else if (response.has_frame() && callbacks_.on_frame) {
          callbacks_.on_frame(response.frame());
        } else if (response.has_notice() && callbacks_.on_notice) {
          callbacks_.on_notice(response.notice());
        }
      }
      ReadNext();
    });
  }
  // "status <code> <message>"
  static grpc::Status ParseStatus(const std::string& text) {
    const std::string prefix = "status ";
    if (text.compare(0, prefix.size(), prefix) != 0) {
      return grpc::Status(grpc::StatusCode::INTERNAL, "an unexpected text message: " + text);
    }
    const std::size_t space = text.find(' ', prefix.size());
    const int code = std::atoi(text.substr(prefix.size(), space - prefix.size()).c_str());
    return grpc::Status(static_cast<grpc::StatusCode>(code),
                        space == std::string::npos ? "" : text.substr(space + 1));
  }
  void Finish(grpc::Status status) {
    if (finished_) return;
    finished_ = true;
    if (callbacks_.on_done) callbacks_.on_done(status);
    std::lock_guard<std::mutex> lock(mutex_);
    status_ = std::move(status);
    done_.notify_all();
  }

  client::DeformClient::StreamCallbacks callbacks_;
  boost::asio::io_context io_;
  boost::beast::websocket::stream<boost::asio::ip::tcp::socket> ws_;
  std::thread thread_;
  // On the I/O thread only.
  std::deque<std::pair<bool, std::string>> outgoing_;  // (text, bytes), the front in flight
  boost::beast::flat_buffer incoming_;
  std::optional<grpc::Status> final_;  // the server's "status" message
  bool finished_ = false;
  bool cancelled_ = false;
  // Shared with the callers' threads.
  std::mutex mutex_;
  std::condition_variable done_;
  bool closed_ = false;
  std::optional<grpc::Status> status_;
};

}  // namespace deform::test_support
