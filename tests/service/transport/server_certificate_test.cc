// The server certificate's checks at start (service/transport/server_certificate.h) on the test
// CA's certificates: names and validity read, a key of another certificate refused, validity
// judged at a given time, host names matched, and the operator's warnings.
#include "service/transport/server_certificate.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <ctime>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/service/support/test_certificates.h"

namespace deform {
namespace {

using service::ServerCertificate;
using test_support::TestCertificates;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::SizeIs;

std::string Read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

StatusOr<ServerCertificate> Inspect(const TestCertificates& certificates,
                                    const std::string& certificate, const std::string& key) {
  return service::InspectServerCertificate(Read(certificates.Path(certificate)),
                                           Read(certificates.Path(key)), certificate, key);
}

TEST(ServerCertificateTest, ReadsTheNamesAndValidityOfAMatchingPair) {
  TestCertificates certificates;
  ASSERT_TRUE(certificates.ok());
  auto served = Inspect(certificates, "server.pem", "server.key");
  ASSERT_TRUE(served.ok()) << served.status().ToString();
  EXPECT_THAT(served->names, ElementsAre("localhost", "localhost", "127.0.0.1", "::1"));
  const std::int64_t now = std::time(nullptr);
  EXPECT_LE(served->not_before, now);
  EXPECT_NEAR(static_cast<double>(served->not_after - served->not_before), 30.0 * 86400, 60.0);
  EXPECT_TRUE(service::CheckCertificateValidity(*served, now, false, "server.pem").ok());

  auto expired = Inspect(certificates, "expired.pem", "expired.key");
  ASSERT_TRUE(expired.ok()) << expired.status().ToString();
  EXPECT_EQ(service::FormatUtc(expired->not_before), "2020-01-01 00:00:00 UTC");
  EXPECT_EQ(service::FormatUtc(expired->not_after), "2020-02-01 00:00:00 UTC");
}

TEST(ServerCertificateTest, RefusesAKeyOfAnotherCertificateAndWhatDoesNotParse) {
  TestCertificates certificates;
  ASSERT_TRUE(certificates.ok());
  auto mismatched = Inspect(certificates, "server.pem", "client.key");
  EXPECT_EQ(mismatched.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(mismatched.status().message(),
              HasSubstr("the private key 'client.key' is not the key of the certificate "
                        "'server.pem'"));
  auto no_certificate = service::InspectServerCertificate(
      "-----BEGIN CERTIFICATE-----\nnot base64\n-----END CERTIFICATE-----\n",
      Read(certificates.Path("server.key")), "bad.pem", "server.key");
  EXPECT_EQ(no_certificate.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(no_certificate.status().message(), HasSubstr("'bad.pem' holds no PEM certificate"));
  // The certificate where the key should be: no private key in it.
  auto no_key = Inspect(certificates, "server.pem", "server.pem");
  EXPECT_EQ(no_key.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(no_key.status().message(), HasSubstr("holds no unencrypted PEM private key"));
}

TEST(ServerCertificateTest, ValidityIsJudgedAtTheGivenTime) {
  ServerCertificate certificate;
  certificate.not_before = 1'000'000;
  certificate.not_after = 2'000'000;
  EXPECT_TRUE(service::CheckCertificateValidity(certificate, 1'500'000, false, "c.pem").ok());
  EXPECT_TRUE(service::CheckCertificateValidity(certificate, 2'000'000, false, "c.pem").ok());
  const Status expired = service::CheckCertificateValidity(certificate, 2'000'001, false, "c.pem");
  EXPECT_EQ(expired.code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(expired.message(), HasSubstr("'c.pem' expired on 1970-01-24 03:33:20 UTC"));
  EXPECT_THAT(expired.message(), HasSubstr("--tls-allow-expired"));
  const Status early = service::CheckCertificateValidity(certificate, 999'999, false, "c.pem");
  EXPECT_EQ(early.code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(early.message(), HasSubstr("is not valid before 1970-01-12 13:46:40 UTC"));
  EXPECT_TRUE(service::CheckCertificateValidity(certificate, 2'000'001, true, "c.pem").ok());
  EXPECT_TRUE(service::CheckCertificateValidity(certificate, 999'999, true, "c.pem").ok());
}

TEST(ServerCertificateTest, HostsMatchNamesAddressesAndOneWildcardLabel) {
  ServerCertificate certificate;
  certificate.names = {"Deform.Ward.Example", "*.sim.example", "10.0.0.5", "::1"};
  EXPECT_TRUE(service::CertificateNamesHost(certificate, "deform.ward.example"));
  EXPECT_TRUE(service::CertificateNamesHost(certificate, "headset-3.sim.example"));
  EXPECT_FALSE(service::CertificateNamesHost(certificate, "sim.example"));
  EXPECT_FALSE(service::CertificateNamesHost(certificate, "a.b.sim.example"));
  EXPECT_FALSE(service::CertificateNamesHost(certificate, "xsim.example"));
  EXPECT_TRUE(service::CertificateNamesHost(certificate, "10.0.0.5"));
  EXPECT_FALSE(service::CertificateNamesHost(certificate, "10.0.0.6"));
  EXPECT_TRUE(service::CertificateNamesHost(certificate, "[::1]"));
  EXPECT_TRUE(service::CertificateNamesHost(certificate, "0:0:0:0:0:0:0:1"));
  EXPECT_FALSE(service::CertificateNamesHost(certificate, ""));
  // An address never matches a DNS name, a wildcard never matches an address.
  certificate.names = {"*.0.0.5"};
  EXPECT_FALSE(service::CertificateNamesHost(certificate, "10.0.0.5"));
}

TEST(ServerCertificateTest, WarnsBeforeExpiryAndWhenTheListenHostIsNotNamed) {
  ServerCertificate certificate;
  certificate.names = {"localhost", "127.0.0.1"};
  const std::int64_t now = 1'800'000'000;
  certificate.not_before = now - 86400;
  certificate.not_after = now + 90 * 86400;
  EXPECT_THAT(service::CertificateWarnings(certificate, "127.0.0.1:50051", now, "c.pem"),
              IsEmpty());
  EXPECT_THAT(service::CertificateWarnings(certificate, "0.0.0.0:50051", now, "c.pem"), IsEmpty());
  EXPECT_THAT(service::CertificateWarnings(certificate, "[::]:50051", now, "c.pem"), IsEmpty());
  auto unnamed = service::CertificateWarnings(certificate, "10.1.2.3:50051", now, "c.pem");
  ASSERT_THAT(unnamed, SizeIs(1));
  EXPECT_THAT(unnamed[0], HasSubstr("does not name '10.1.2.3'"));
  EXPECT_THAT(unnamed[0], HasSubstr("it names localhost, 127.0.0.1"));
  certificate.not_after = now + 10 * 86400 + 5;
  auto soon = service::CertificateWarnings(certificate, "localhost:50051", now, "c.pem");
  ASSERT_THAT(soon, SizeIs(1));
  EXPECT_THAT(soon[0], HasSubstr("'c.pem' expires on"));
  EXPECT_THAT(soon[0], HasSubstr("in 10 days"));
  certificate.not_after = now - 1;  // served only with --tls-allow-expired
  auto expired = service::CertificateWarnings(certificate, "localhost:50051", now, "c.pem");
  ASSERT_THAT(expired, SizeIs(1));
  EXPECT_THAT(expired[0], HasSubstr("is outside its validity"));
  EXPECT_THAT(expired[0], HasSubstr("--tls-allow-expired"));
}

}  // namespace
}  // namespace deform
