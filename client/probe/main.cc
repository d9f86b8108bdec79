// deform-health-probe: asks a server's standard gRPC health service whether it is serving.
//
//   deform-health-probe [--target HOST:PORT] [--service NAME] [--connect-timeout-ms MS]
//                       [--timeout-ms MS] [--tls-ca PEM] [--tls-cert PEM --tls-key PEM]
//                       [--tls-server-name NAME]
//
// The TLS flags (and their environment variables, DEFORM_TLS_CA etc.) are the other clients'
// (client/cli/command_line.h), so a container that sets them for deformd's clients health-checks a
// TLS server too. The health service itself needs no token.
//
// Exit codes, those of grpc-ecosystem/grpc-health-probe (docs/clients/probe.md), so scripts and
// orchestrators written for it read this one the same way; the reason goes to stderr:
//   0  the status is SERVING
//   1  invalid arguments, including TLS files that cannot be read (grpc_health_probe's code for
//      credentials it cannot set up)
//   2  no connection within --connect-timeout-ms (nothing listening, or the TLS handshake failed)
//   3  the Check RPC failed (e.g. NOT_FOUND for an unknown --service, its deadline)
//   4  the RPC succeeded and the status is not SERVING (NOT_SERVING: deformd draining)
// Used by the container's HEALTHCHECK (no such probe is packaged in Debian).
#include <grpcpp/grpcpp.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>
#include <string>

#include "cli/command_line.h"
#include "core/base/build_info.h"
#include "health.grpc.pb.h"
#include "lib/deform_client.h"

namespace {

enum ExitCode {
  kServing = 0,
  kInvalidArguments = 1,
  kConnectionFailure = 2,
  kRpcFailure = 3,
  kUnhealthy = 4,
};

}  // namespace

int main(int argc, char** argv) {
  std::string target = "127.0.0.1:50051";
  std::string service;
  int connect_timeout_ms = 2000;
  int timeout_ms = 2000;
  CLI::App app{"Checks a gRPC server's health service; exit 0 when SERVING"};
  app.add_option("--target", target, "Server address host:port")->capture_default_str();
  app.add_option("--service", service, "Service name to check (empty: the whole server)");
  app.add_option("--connect-timeout-ms", connect_timeout_ms,
                 "How long to wait for the connection (exit 2 when it is not made)")
      ->capture_default_str()
      ->check(CLI::Range(1, 600000));
  app.add_option("--timeout-ms", timeout_ms, "Deadline of the Check RPC (exit 3 when it passes)")
      ->capture_default_str()
      ->check(CLI::Range(1, 600000));
  deform::cli::SecurityArgs security;
  deform::cli::AddSecurityFlags(app, &security);
  app.set_version_flag("--version", deform::VersionLine("deform-health-probe"));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "deform-health-probe: " << e.what() << "\n";
    return kInvalidArguments;
  }

  deform::client::ClientOptions options;
  const grpc::Status configured = deform::cli::MakeClientOptions(security, &options);
  if (!configured.ok()) {
    std::cerr << "deform-health-probe: " << configured.error_message() << "\n";
    return kInvalidArguments;
  }
  auto channel = deform::client::MakeDeformChannel(target, options);
  if (!channel->WaitForConnected(std::chrono::system_clock::now() +
                                 std::chrono::milliseconds(connect_timeout_ms))) {
    std::cerr << "deform-health-probe: " << target << ": no connection within "
              << connect_timeout_ms << " ms\n";
    return kConnectionFailure;
  }
  auto stub = grpc::health::v1::Health::NewStub(channel);
  grpc::ClientContext context;
  deform::client::AddCallCredentials(options, &context);
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(timeout_ms));
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = stub->Check(&context, request, &response);
  if (!status.ok()) {
    std::cerr << "deform-health-probe: " << target << ": health check failed: code "
              << status.error_code() << ": " << status.error_message() << "\n";
    return kRpcFailure;
  }
  if (response.status() != grpc::health::v1::HealthCheckResponse::SERVING) {
    std::cerr << "deform-health-probe: " << target << " is "
              << grpc::health::v1::HealthCheckResponse::ServingStatus_Name(response.status())
              << "\n";
    return kUnhealthy;
  }
  std::cout << "SERVING\n";
  return kServing;
}
