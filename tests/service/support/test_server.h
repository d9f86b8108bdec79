// An in-process deformd for tests: the real server on 127.0.0.1 with a free port, and a client
// connected to it through the client library.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "deform_client.h"
#include "service/rpc/deform_server.h"
#include "service/base/service_options.h"

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
  explicit TestServer(service::ServerOptions options = TestServerOptions(),
                      const std::string& token_file = "")
      : server_(std::make_unique<service::DeformServer>(options)) {
    if (!token_file.empty()) {
      const Status tokens = server_->UseTokenFile(token_file);
      EXPECT_TRUE(tokens.ok()) << tokens.ToString();
    }
    const Status started = server_->Start();
    EXPECT_TRUE(started.ok()) << started.ToString();
    target_ = "127.0.0.1:" + std::to_string(server_->port());
  }

  service::DeformServer& server() { return *server_; }
  const std::string& target() const { return target_; }
  // A new client (its own channel, so its own connection).
  std::unique_ptr<client::DeformClient> NewClient(client::ClientOptions options = {}) const {
    return std::make_unique<client::DeformClient>(target_, options);
  }

 private:
  std::unique_ptr<service::DeformServer> server_;
  std::string target_;
};

}  // namespace deform::test_support
