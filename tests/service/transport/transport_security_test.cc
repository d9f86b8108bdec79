// TLS on the gRPC port, through the real client library: a TLS server serves a TLS client that
// trusts its CA and refuses a plaintext client and a client trusting another CA; with a client CA
// (mutual TLS) it refuses a client without a certificate or with one from another CA. Without a
// certificate the server refuses to serve plaintext on a non-loopback address unless asked to. An
// expired certificate, or another certificate's key, refuses to start.
#include "service/transport/transport_security.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "service/rpc/deform_server.h"
#include "tests/service/support/test_certificates.h"
#include "tests/service/support/test_server.h"

namespace deform {
namespace {

using test_support::TestCertificates;
using test_support::TestServer;
using test_support::TestServerOptions;
using ::testing::HasSubstr;

service::ServerOptions TlsServerOptions(const TestCertificates& certificates, bool mutual) {
  service::ServerOptions options = TestServerOptions();
  options.security.cert_file = certificates.Path("server.pem");
  options.security.key_file = certificates.Path("server.key");
  if (mutual) options.security.client_ca_file = certificates.Path("ca.pem");
  return options;
}

client::ClientOptions TlsClientOptions(const TestCertificates& certificates,
                                       const std::string& ca = "ca.pem",
                                       const std::string& client_certificate = "") {
  client::ClientOptions options;
  const grpc::Status loaded = client::LoadClientTlsFiles(
      certificates.Path(ca),
      client_certificate.empty() ? "" : certificates.Path(client_certificate + ".pem"),
      client_certificate.empty() ? "" : certificates.Path(client_certificate + ".key"),
      &options.tls);
  EXPECT_TRUE(loaded.ok()) << loaded.error_message();
  options.unary_deadline_ms = 10'000;
  return options;
}

// ListMeshes's status from a fresh client with `options`.
grpc::Status List(const TestServer& server, const client::ClientOptions& options) {
  auto client = server.NewClient(options);
  std::vector<v1::MeshSummary> meshes;
  return client->ListMeshes(&meshes);
}

TEST(TransportSecurityTest, TlsServerServesATlsClientAndRefusesPlaintext) {
  TestCertificates certificates;
  ASSERT_TRUE(certificates.ok());
  TestServer server(TlsServerOptions(certificates, false));
  auto client = server.NewClient(TlsClientOptions(certificates));
  ASSERT_TRUE(client->WaitForReady(60'000));
  v1::MeshSummary summary;
  const grpc::Status loaded = client->LoadPhantom(300, {}, &summary);
  ASSERT_TRUE(loaded.ok()) << loaded.error_message();
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(client->ListMeshes(&meshes).ok());
  EXPECT_EQ(meshes.size(), 1u);

  client::ClientOptions plaintext;
  plaintext.unary_deadline_ms = 10'000;
  EXPECT_EQ(List(server, plaintext).error_code(), grpc::StatusCode::UNAVAILABLE);
  // A client that trusts another CA refuses the server's certificate.
  EXPECT_EQ(List(server, TlsClientOptions(certificates, "other-ca.pem")).error_code(),
            grpc::StatusCode::UNAVAILABLE);
}

TEST(TransportSecurityTest, ServerNameOverrideChecksTheCertificateName) {
  TestCertificates certificates;
  ASSERT_TRUE(certificates.ok());
  TestServer server(TlsServerOptions(certificates, false));
  client::ClientOptions right = TlsClientOptions(certificates);
  right.tls.server_name = "localhost";
  EXPECT_TRUE(List(server, right).ok());
  client::ClientOptions wrong = TlsClientOptions(certificates);
  wrong.tls.server_name = "not-the-server.example";
  EXPECT_EQ(List(server, wrong).error_code(), grpc::StatusCode::UNAVAILABLE);
}

TEST(TransportSecurityTest, MutualTlsRefusesClientsWithoutACertificateFromItsCa) {
  TestCertificates certificates;
  ASSERT_TRUE(certificates.ok());
  TestServer server(TlsServerOptions(certificates, true));
  EXPECT_EQ(List(server, TlsClientOptions(certificates)).error_code(),
            grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(List(server, TlsClientOptions(certificates, "ca.pem", "other-client")).error_code(),
            grpc::StatusCode::UNAVAILABLE);
  const grpc::Status with_certificate =
      List(server, TlsClientOptions(certificates, "ca.pem", "client"));
  EXPECT_TRUE(with_certificate.ok()) << with_certificate.error_message();
}

TEST(TransportSecurityTest, PlaintextOnANonLoopbackAddressOnlyWhenAskedFor) {
  service::ServerOptions options = TestServerOptions();
  options.listen_address = "0.0.0.0:0";
  {
    service::DeformServer server(options);
    const Status started = server.Start();
    EXPECT_EQ(started.code(), StatusCode::kFailedPrecondition);
    EXPECT_THAT(started.message(), HasSubstr("--plaintext"));
  }
  options.security.allow_plaintext = true;
  service::DeformServer server(options);
  EXPECT_TRUE(server.Start().ok());
}

TEST(TransportSecurityTest, CertificateSettingsAreChecked) {
  service::ServerOptions options = TestServerOptions();
  options.security.cert_file = "/nonexistent/server.pem";
  {
    service::DeformServer server(options);
    EXPECT_EQ(server.Start().code(), StatusCode::kFailedPrecondition);  // no key
  }
  options.security.key_file = "/nonexistent/server.key";
  service::DeformServer server(options);
  const Status started = server.Start();
  EXPECT_EQ(started.code(), StatusCode::kNotFound);
  EXPECT_THAT(started.message(), HasSubstr("/nonexistent/server.pem"));
}

TEST(TransportSecurityTest, AnExpiredCertificateOrAnotherCertificatesKeyRefusesToStart) {
  TestCertificates certificates;
  ASSERT_TRUE(certificates.ok());
  service::ServerOptions options = TestServerOptions();
  options.security.cert_file = certificates.Path("expired.pem");
  options.security.key_file = certificates.Path("expired.key");
  {
    service::DeformServer server(options);
    const Status started = server.Start();
    EXPECT_EQ(started.code(), StatusCode::kFailedPrecondition);
    EXPECT_THAT(started.message(), HasSubstr("expired on 2020-02-01 00:00:00 UTC"));
    EXPECT_THAT(started.message(), HasSubstr(certificates.Path("expired.pem")));
  }
  options.security.allow_expired_certificate = true;  // asked for: it serves
  {
    service::DeformServer server(options);
    const Status started = server.Start();
    EXPECT_TRUE(started.ok()) << started.ToString();
  }
  options.security.allow_expired_certificate = false;
  options.security.cert_file = certificates.Path("server.pem");
  options.security.key_file = certificates.Path("client.key");
  service::DeformServer server(options);
  const Status started = server.Start();
  EXPECT_EQ(started.code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(started.message(), HasSubstr("is not the key of the certificate"));
}

TEST(TransportSecurityTest, LoopbackAddresses) {
  EXPECT_TRUE(service::IsLoopbackAddress("127.0.0.1:50051"));
  EXPECT_TRUE(service::IsLoopbackAddress("127.1.2.3:0"));
  EXPECT_TRUE(service::IsLoopbackAddress("[::1]:50051"));
  EXPECT_TRUE(service::IsLoopbackAddress("localhost:50051"));
  EXPECT_FALSE(service::IsLoopbackAddress("0.0.0.0:50051"));
  EXPECT_FALSE(service::IsLoopbackAddress("[::]:50051"));
  EXPECT_FALSE(service::IsLoopbackAddress("10.0.0.5:50051"));
  EXPECT_FALSE(service::IsLoopbackAddress("127.evil.example:50051"));
}

}  // namespace
}  // namespace deform
