// Certificates for the TLS tests, made by scripts/make-test-certificates.sh (openssl) into a fresh
// temporary directory: a CA, a server certificate for localhost/127.0.0.1, a client certificate,
// and a second CA with a client it signed.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace deform::test_support {

class TestCertificates {
 public:
  TestCertificates() {
    char pattern[] = "/tmp/deform-certs-XXXXXX";
    const char* made = mkdtemp(pattern);
    EXPECT_NE(made, nullptr);
    dir_ = made == nullptr ? "" : made;
    const std::string command = std::string(DEFORM_SOURCE_DIR) +
                                "/scripts/make-test-certificates.sh " + dir_ + " >/dev/null";
    ok_ = std::system(command.c_str()) == 0;
    EXPECT_TRUE(ok_) << "scripts/make-test-certificates.sh failed (is openssl installed?)";
  }
  ~TestCertificates() {
    std::error_code ignored;
    if (!dir_.empty()) std::filesystem::remove_all(dir_, ignored);
  }
  TestCertificates(const TestCertificates&) = delete;
  TestCertificates& operator=(const TestCertificates&) = delete;

  bool ok() const { return ok_; }
  // A file of the directory, e.g. Path("server.pem").
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }

 private:
  std::string dir_;
  bool ok_ = false;
};

}  // namespace deform::test_support
