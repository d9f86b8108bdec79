// The server's TLS certificate as deformd checks it at start, before it listens: the chain's first
// certificate parses, the private key is that certificate's key, and the certificate is valid now.
// A server that started with an expired certificate or the wrong key would log "listening (TLS)"
// and then fail every handshake; these checks make the start fail instead, with the file named.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"

namespace deform::service {

struct ServerCertificate {
  // The names clients may dial: the subjectAltName's DNS names and IP addresses (IPv6 as
  // "::1"), or the subject's common name when there is no subjectAltName.
  std::vector<std::string> names;
  // Validity, Unix seconds (UTC).
  std::int64_t not_before = 0;
  std::int64_t not_after = 0;
};

// Reads the first certificate of `certificate_pem` and checks that `key_pem` holds its private
// key. FAILED_PRECONDITION naming the file (`certificate_path`, `key_path`) when either does not
// parse or the key belongs to another certificate.
StatusOr<ServerCertificate> InspectServerCertificate(std::string_view certificate_pem,
                                                     std::string_view key_pem,
                                                     const std::string& certificate_path,
                                                     const std::string& key_path);

// FAILED_PRECONDITION when `now` (Unix seconds) is after the certificate's end or before its
// start, naming the file, the date and the flag that accepts it (--tls-allow-expired), unless
// `allow_expired`.
Status CheckCertificateValidity(const ServerCertificate& certificate, std::int64_t now,
                                bool allow_expired, const std::string& certificate_path);

// Whether a client dialling `host` (a DNS name or an IP address, IPv6 with or without brackets)
// would find it among the certificate's names: exact, case-insensitive, or a "*.example" name
// matching one leftmost label. Wildcard-free addresses (0.0.0.0, [::]) name no host: false.
bool CertificateNamesHost(const ServerCertificate& certificate, std::string_view host);

// A served certificate warns this long before it expires.
inline constexpr std::int64_t kCertificateExpiryWarningSeconds = 30 * 24 * 3600;

// What the operator should read when the certificate is served at `listen_address` ("host:port"):
// that it is outside its validity at `now` (served only with --tls-allow-expired) or expires
// within kCertificateExpiryWarningSeconds of it, and that the listen host, when
// it names one (not 0.0.0.0 or [::]), is not among its names, so clients dialling it would refuse
// it. Empty when neither.
std::vector<std::string> CertificateWarnings(const ServerCertificate& certificate,
                                             std::string_view listen_address, std::int64_t now,
                                             const std::string& certificate_path);

// "2026-12-31 23:59:59 UTC".
std::string FormatUtc(std::int64_t unix_seconds);

}  // namespace deform::service
