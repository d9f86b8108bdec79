#include "service/transport/transport_security.h"

#include <grpcpp/security/server_credentials.h>

#include <ctime>
#include <fstream>
#include <sstream>

#include "service/base/listen_address.h"
#include "service/transport/server_certificate.h"

namespace deform::service {
namespace {

StatusOr<std::string> ReadPemFile(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound("cannot open the " + std::string(what) + " '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad() || text.str().empty()) {
    return Status::NotFound("cannot read the " + std::string(what) + " '" + path + "'");
  }
  return text.str();
}

}  // namespace

bool IsLoopbackAddress(const std::string& listen_address) {
  const std::string_view host = SplitListenAddress(listen_address).host;
  if (host == "[::1]" || host == "localhost") return true;
  if (host.rfind("127.", 0) != 0) return false;
  // A dotted IPv4 address in 127.0.0.0/8, not a name that starts with "127.".
  return host.find_first_not_of("0123456789.") == std::string::npos;
}

StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const TransportSecurity& security, const std::string& listen_address, std::string* description,
    ServerCertificate* served_certificate) {
  if (security.cert_file.empty() != security.key_file.empty()) {
    return Status::FailedPrecondition(
        "a TLS certificate needs its key and a key its certificate (--tls-cert and --tls-key)");
  }
  if (security.cert_file.empty()) {
    if (!security.client_ca_file.empty()) {
      return Status::FailedPrecondition(
          "a client CA (--tls-client-ca) needs the server's own certificate (--tls-cert, "
          "--tls-key)");
    }
    if (!security.allow_plaintext && !IsLoopbackAddress(listen_address)) {
      return Status::FailedPrecondition(
          "refusing to serve plaintext on the non-loopback address '" + listen_address +
          "': give a certificate (--tls-cert, --tls-key) or ask for plaintext (--plaintext)");
    }
    *description = "plaintext";
    return grpc::InsecureServerCredentials();
  }
  grpc::SslServerCredentialsOptions options;
  DEFORM_ASSIGN_OR_RETURN(std::string certificate, ReadPemFile(security.cert_file, "certificate"));
  DEFORM_ASSIGN_OR_RETURN(std::string key, ReadPemFile(security.key_file, "private key"));
  DEFORM_ASSIGN_OR_RETURN(
      ServerCertificate inspected,
      InspectServerCertificate(certificate, key, security.cert_file, security.key_file));
  DEFORM_RETURN_IF_ERROR(CheckCertificateValidity(
      inspected, std::time(nullptr), security.allow_expired_certificate, security.cert_file));
  if (served_certificate != nullptr) *served_certificate = std::move(inspected);
  options.pem_key_cert_pairs.push_back({std::move(key), std::move(certificate)});
  if (security.client_ca_file.empty()) {
    options.client_certificate_request = GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE;
    *description = "TLS";
  } else {
    DEFORM_ASSIGN_OR_RETURN(options.pem_root_certs,
                            ReadPemFile(security.client_ca_file, "client CA"));
    options.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
    *description = "mutual TLS";
  }
  return grpc::SslServerCredentials(options);
}

}  // namespace deform::service
