// An in-process deformd for tests: the real server on 127.0.0.1 with a free port, and a client
// connected to it through the client library.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "deform_client.h"
#include "service/deform_server.h"
#include "service/service_options.h"

namespace deform::test_support {

inline service::ServerOptions TestServerOptions() {
  service::ServerOptions options;
  options.listen_address = "127.0.0.1:0";
  options.workers = 2;
  return options;
}

class TestServer {
 public:
  explicit TestServer(service::ServerOptions options = TestServerOptions())
      : server_(std::make_unique<service::DeformServer>(options)) {
    const Status started = server_->Start();
    EXPECT_TRUE(started.ok()) << started.ToString();
    target_ = "127.0.0.1:" + std::to_string(server_->port());
  }

  service::DeformServer& server() { return *server_; }
  const std::string& target() const { return target_; }
  // A new client (its own channel, so its own connection).
  std::unique_ptr<client::DeformClient> NewClient() const {
    return std::make_unique<client::DeformClient>(target_);
  }

 private:
  std::unique_ptr<service::DeformServer> server_;
  std::string target_;
};

}  // namespace deform::test_support
