// deform-health-probe's exit codes, those of grpc-ecosystem/grpc-health-probe: 0 SERVING,
// 1 invalid arguments (a TLS file that cannot be read included), 2 no connection, 3 the RPC
// failed, 4 not SERVING. Against an in-process server with gRPC's standard health service.
#include <arpa/inet.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include "tests/service/support/temp_dir.h"

namespace deform {
namespace {

using test_support::TempDir;

// The probe's exit code for `arguments`; -1 when it did not exit normally.
int Probe(const std::string& arguments, const TempDir& dir, std::string* stderr_text) {
  const std::string err = dir.Path("probe.err");
  const int status = std::system(
      (std::string(DEFORM_PROBE_PATH) + " " + arguments + " >/dev/null 2>" + err).c_str());
  std::ifstream in(err);
  *stderr_text = std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A loopback port that nothing listens on (bound, then closed).
int ClosedPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  EXPECT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), size), 0);
  EXPECT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size), 0);
  ::close(fd);
  return ntohs(address.sin_port);
}

class ProbeExitCodesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    grpc::EnableDefaultHealthCheckService(true);
    grpc::ServerBuilder builder;
    int port = 0;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
    server_ = builder.BuildAndStart();
    ASSERT_NE(server_, nullptr);
    target_ = "127.0.0.1:" + std::to_string(port);
    grpc::HealthCheckServiceInterface* health = server_->GetHealthCheckService();
    ASSERT_NE(health, nullptr);
    health->SetServingStatus("deform.test.Serving", true);
    health->SetServingStatus("deform.test.Draining", false);
  }
  void TearDown() override {
    if (server_ != nullptr) server_->Shutdown();
  }

  TempDir dir_;
  std::unique_ptr<grpc::Server> server_;
  std::string target_;
};

TEST_F(ProbeExitCodesTest, ZeroWhenServing) {
  std::string err;
  EXPECT_EQ(Probe("--target " + target_, dir_, &err), 0) << err;
  EXPECT_EQ(Probe("--target " + target_ + " --service deform.test.Serving", dir_, &err), 0) << err;
}

TEST_F(ProbeExitCodesTest, OneForInvalidArguments) {
  std::string err;
  EXPECT_EQ(Probe("--target " + target_ + " --no-such-flag", dir_, &err), 1) << err;
  EXPECT_EQ(Probe("--target " + target_ + " --timeout-ms 0", dir_, &err), 1) << err;
  // TLS credentials that cannot be set up: grpc_health_probe exits 1 for those too.
  EXPECT_EQ(Probe("--target " + target_ + " --tls-ca " + dir_.Path("missing-ca.pem"), dir_, &err),
            1)
      << err;
  EXPECT_NE(err.find("missing-ca.pem"), std::string::npos) << err;
}

TEST_F(ProbeExitCodesTest, TwoWhenNoConnectionIsMade) {
  std::string err;
  const std::string closed = "127.0.0.1:" + std::to_string(ClosedPort());
  EXPECT_EQ(Probe("--target " + closed + " --connect-timeout-ms 500", dir_, &err), 2) << err;
  EXPECT_NE(err.find("no connection"), std::string::npos) << err;
}

TEST_F(ProbeExitCodesTest, ThreeWhenTheRpcFails) {
  std::string err;
  EXPECT_EQ(Probe("--target " + target_ + " --service no.such.Service", dir_, &err), 3) << err;
  EXPECT_NE(err.find("health check failed"), std::string::npos) << err;
}

TEST_F(ProbeExitCodesTest, FourWhenNotServing) {
  std::string err;
  EXPECT_EQ(Probe("--target " + target_ + " --service deform.test.Draining", dir_, &err), 4) << err;
  EXPECT_NE(err.find("NOT_SERVING"), std::string::npos) << err;
}

// The image's health check reads only 0 and 1 (Docker reserves 2): every failure exits 1.
TEST_F(ProbeExitCodesTest, TheContainersHealthCheckExitsOneForEveryFailure) {
  const std::string probe_dir =
      std::string(DEFORM_PROBE_PATH).substr(0, std::string(DEFORM_PROBE_PATH).rfind('/'));
  const std::string check = "PATH=" + probe_dir + ":$PATH sh " + DEFORM_SOURCE_DIR +
                            "/docker/healthcheck.sh >/dev/null 2>/dev/null";
  const std::string port = target_.substr(target_.rfind(':') + 1);
  int status = std::system(("DEFORMD_PORT=" + port + " " + check).c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  status = std::system(("DEFORMD_PORT=" + std::to_string(ClosedPort()) + " " + check).c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << status;
}

}  // namespace
}  // namespace deform
