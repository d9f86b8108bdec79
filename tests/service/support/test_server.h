// An in-process deformd for tests: the real server on 127.0.0.1 with a free port, and a client
// connected to it through the client library; optionally its HTTP port too (the WebSocket
// transport, rpc/web_server.h), on another free port.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "deform_client.h"
#include "service/base/service_options.h"
#include "service/rpc/deform_server.h"
#include "service/rpc/web_server.h"

namespace deform::test_support {

inline service::ServerOptions TestServerOptions() {
  service::ServerOptions options;
  options.listen_address = "127.0.0.1:0";
  options.workers = 2;
  return options;
}

class TestServer {
 public:
  // `token_file`: authenticate calls with it (DeformServer::UseTokenFile); empty: no tokens.
  // `with_web`: serve the HTTP port as well (its static root: the viewer's sources) with
  // `web_options` (their address and static root are the test's).
  explicit TestServer(service::ServerOptions options = TestServerOptions(),
                      const std::string& token_file = "", bool with_web = false,
                      web::WebOptions web_options = {})
      : server_(std::make_unique<service::DeformServer>(options)) {
    if (!token_file.empty()) {
      const Status tokens = server_->UseTokenFile(token_file);
      EXPECT_TRUE(tokens.ok()) << tokens.ToString();
    }
    if (with_web) {
      web_options.address = "127.0.0.1:0";
      web_options.static_root = std::string(DEFORM_SOURCE_DIR) + "/client/web";
      web_ = std::make_unique<web::WebServer>(&server_->context(), web_options);
      server_->AddTransportStop([this](std::chrono::milliseconds grace) { web_->Stop(grace); });
    }
    const Status started = server_->Start();
    EXPECT_TRUE(started.ok()) << started.ToString();
    target_ = "127.0.0.1:" + std::to_string(server_->port());
    if (web_ != nullptr) {
      const Status web_started = web_->Start();
      EXPECT_TRUE(web_started.ok()) << web_started.ToString();
    }
  }
  ~TestServer() { server_->Shutdown(); }

  // The HTTP port (with_web only).
  int web_port() const { return web_ != nullptr ? web_->port() : 0; }

  service::DeformServer& server() { return *server_; }
  // deformd_refused_total{reason="..."} as the server counted it now (0 when absent).
  std::uint64_t Refused(const std::string& reason) {
    const std::string page = server_->context().metrics().Serialize();
    const std::string name = "deformd_refused_total{reason=\"" + reason + "\"} ";
    const std::size_t at = page.find(name);
    return at == std::string::npos ? 0 : std::stoull(page.substr(at + name.size()));
  }
  const std::string& target() const { return target_; }
  // A new client (its own channel, so its own connection).
  std::unique_ptr<client::DeformClient> NewClient(client::ClientOptions options = {}) const {
    return std::make_unique<client::DeformClient>(target_, options);
  }

 private:
  std::unique_ptr<web::WebServer> web_;  // declared first: outlives the server's Shutdown
  std::unique_ptr<service::DeformServer> server_;
  std::string target_;
};

}  // namespace deform::test_support
