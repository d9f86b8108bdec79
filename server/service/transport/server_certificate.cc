#include "service/transport/server_certificate.h"

#include <arpa/inet.h>
#include <openssl/asn1.h>
#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <algorithm>
#include <cctype>
#include <ctime>
#include <memory>

#include "service/base/listen_address.h"

namespace deform::service {
namespace {

struct BioFree {
  void operator()(BIO* bio) const { BIO_free(bio); }
};
struct X509Free {
  void operator()(X509* certificate) const { X509_free(certificate); }
};
struct KeyFree {
  void operator()(EVP_PKEY* key) const { EVP_PKEY_free(key); }
};
struct NamesFree {
  void operator()(GENERAL_NAMES* names) const { GENERAL_NAMES_free(names); }
};

std::unique_ptr<BIO, BioFree> MemoryBio(std::string_view text) {
  return std::unique_ptr<BIO, BioFree>(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
}

// No passphrase: an encrypted key fails to parse instead of prompting on a terminal.
int NoPassphrase(char*, int, int, void*) { return 0; }

StatusOr<std::int64_t> UnixTime(const ASN1_TIME* time) {
  std::tm parts{};
  if (time == nullptr || ASN1_TIME_to_tm(time, &parts) != 1) {
    return Status::FailedPrecondition("unreadable validity date");
  }
  return static_cast<std::int64_t>(timegm(&parts));
}

std::string Lower(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return lower;
}

// The textual form inet_ntop gives an IPv4 or IPv6 address, or "" when `text` is not one.
std::string CanonicalAddress(std::string_view text) {
  std::string address(text);
  if (address.size() >= 2 && address.front() == '[' && address.back() == ']') {
    address = address.substr(1, address.size() - 2);
  }
  unsigned char bytes[16];
  char out[INET6_ADDRSTRLEN];
  if (inet_pton(AF_INET, address.c_str(), bytes) == 1) {
    return inet_ntop(AF_INET, bytes, out, sizeof out) ? out : "";
  }
  if (inet_pton(AF_INET6, address.c_str(), bytes) == 1) {
    return inet_ntop(AF_INET6, bytes, out, sizeof out) ? out : "";
  }
  return "";
}

std::string AddressText(const ASN1_OCTET_STRING* address) {
  char out[INET6_ADDRSTRLEN];
  const int length = ASN1_STRING_length(address);
  const unsigned char* bytes = ASN1_STRING_get0_data(address);
  if (length == 4) return inet_ntop(AF_INET, bytes, out, sizeof out) ? out : "";
  if (length == 16) return inet_ntop(AF_INET6, bytes, out, sizeof out) ? out : "";
  return "";
}

std::vector<std::string> CertificateNames(X509* certificate) {
  std::vector<std::string> names;
  std::unique_ptr<GENERAL_NAMES, NamesFree> alternatives(static_cast<GENERAL_NAMES*>(
      X509_get_ext_d2i(certificate, NID_subject_alt_name, nullptr, nullptr)));
  if (alternatives != nullptr) {
    for (int i = 0; i < sk_GENERAL_NAME_num(alternatives.get()); ++i) {
      const GENERAL_NAME* name = sk_GENERAL_NAME_value(alternatives.get(), i);
      if (name->type == GEN_DNS) {
        const ASN1_IA5STRING* dns = name->d.dNSName;
        names.emplace_back(reinterpret_cast<const char*>(ASN1_STRING_get0_data(dns)),
                           static_cast<std::size_t>(ASN1_STRING_length(dns)));
      } else if (name->type == GEN_IPADD) {
        std::string address = AddressText(name->d.iPAddress);
        if (!address.empty()) names.push_back(std::move(address));
      }
    }
    return names;
  }
  X509_NAME* subject = X509_get_subject_name(certificate);
  const int index = X509_NAME_get_index_by_NID(subject, NID_commonName, -1);
  if (index >= 0) {
    const ASN1_STRING* common = X509_NAME_ENTRY_get_data(X509_NAME_get_entry(subject, index));
    names.emplace_back(reinterpret_cast<const char*>(ASN1_STRING_get0_data(common)),
                       static_cast<std::size_t>(ASN1_STRING_length(common)));
  }
  return names;
}

}  // namespace

StatusOr<ServerCertificate> InspectServerCertificate(std::string_view certificate_pem,
                                                     std::string_view key_pem,
                                                     const std::string& certificate_path,
                                                     const std::string& key_path) {
  auto certificate_bio = MemoryBio(certificate_pem);
  std::unique_ptr<X509, X509Free> certificate(
      certificate_bio ? PEM_read_bio_X509(certificate_bio.get(), nullptr, NoPassphrase, nullptr)
                      : nullptr);
  auto key_bio = MemoryBio(key_pem);
  std::unique_ptr<EVP_PKEY, KeyFree> key(
      key_bio ? PEM_read_bio_PrivateKey(key_bio.get(), nullptr, NoPassphrase, nullptr) : nullptr);
  const bool matches = certificate != nullptr && key != nullptr &&
                       X509_check_private_key(certificate.get(), key.get()) == 1;
  ERR_clear_error();  // leave no error of ours in this thread's queue for gRPC's TLS to find
  if (certificate == nullptr) {
    return Status::FailedPrecondition("the certificate '" + certificate_path +
                                      "' holds no PEM certificate (--tls-cert)");
  }
  if (key == nullptr) {
    return Status::FailedPrecondition("the private key '" + key_path +
                                      "' holds no unencrypted PEM private key (--tls-key)");
  }
  if (!matches) {
    return Status::FailedPrecondition("the private key '" + key_path +
                                      "' is not the key of the certificate '" + certificate_path +
                                      "' (--tls-key, --tls-cert)");
  }
  ServerCertificate summary;
  summary.names = CertificateNames(certificate.get());
  auto not_before = UnixTime(X509_get0_notBefore(certificate.get()));
  auto not_after = UnixTime(X509_get0_notAfter(certificate.get()));
  if (!not_before.ok() || !not_after.ok()) {
    return Status::FailedPrecondition("the certificate '" + certificate_path +
                                      "' has an unreadable validity date");
  }
  summary.not_before = *not_before;
  summary.not_after = *not_after;
  return summary;
}

Status CheckCertificateValidity(const ServerCertificate& certificate, std::int64_t now,
                                bool allow_expired, const std::string& certificate_path) {
  if (allow_expired) return Status::Ok();
  if (now > certificate.not_after) {
    return Status::FailedPrecondition(
        "the certificate '" + certificate_path + "' expired on " +
        FormatUtc(certificate.not_after) +
        ": every client would refuse it; renew it, or start with --tls-allow-expired");
  }
  if (now < certificate.not_before) {
    return Status::FailedPrecondition(
        "the certificate '" + certificate_path + "' is not valid before " +
        FormatUtc(certificate.not_before) +
        ": every client would refuse it; check the clock, or start with --tls-allow-expired");
  }
  return Status::Ok();
}

bool CertificateNamesHost(const ServerCertificate& certificate, std::string_view host) {
  const std::string address = CanonicalAddress(host);
  if (!address.empty()) {
    return std::find(certificate.names.begin(), certificate.names.end(), address) !=
           certificate.names.end();
  }
  const std::string wanted = Lower(host);
  if (wanted.empty()) return false;
  for (const std::string& name : certificate.names) {
    const std::string lower = Lower(name);
    if (lower == wanted) return true;
    // "*.example.org" matches "a.example.org", one label, not "example.org" or "a.b.example.org".
    if (lower.size() > 2 && lower.compare(0, 2, "*.") == 0) {
      const std::size_t dot = wanted.find('.');
      if (dot != std::string::npos && dot > 0 &&
          wanted.compare(dot, std::string::npos, lower, 1) == 0) {
        return true;
      }
    }
  }
  return false;
}

std::vector<std::string> CertificateWarnings(const ServerCertificate& certificate,
                                             std::string_view listen_address, std::int64_t now,
                                             const std::string& certificate_path) {
  std::vector<std::string> warnings;
  if (now > certificate.not_after || now < certificate.not_before) {
    warnings.push_back("the certificate '" + certificate_path + "' is outside its validity (" +
                       FormatUtc(certificate.not_before) + " to " +
                       FormatUtc(certificate.not_after) +
                       "), served because of --tls-allow-expired: clients will refuse it");
  } else if (certificate.not_after &&
             certificate.not_after - now < kCertificateExpiryWarningSeconds) {
    warnings.push_back("the certificate '" + certificate_path + "' expires on " +
                       FormatUtc(certificate.not_after) + ", in " +
                       std::to_string((certificate.not_after - now) / 86400) +
                       " days: renew it before clients refuse it");
  }
  const std::string_view host = SplitListenAddress(listen_address).host;
  const std::string address = CanonicalAddress(host);
  const bool any_address = address == "0.0.0.0" || address == "::";
  if (!host.empty() && !any_address && !CertificateNamesHost(certificate, host)) {
    std::string names;
    for (const std::string& name : certificate.names) names += (names.empty() ? "" : ", ") + name;
    warnings.push_back("the certificate '" + certificate_path + "' does not name '" +
                       std::string(host) + "', the listen address's host (it names " +
                       (names.empty() ? std::string("nothing") : names) +
                       "): clients dialling that host will refuse it");
  }
  return warnings;
}

std::string FormatUtc(std::int64_t unix_seconds) {
  const std::time_t time = static_cast<std::time_t>(unix_seconds);
  std::tm parts{};
  gmtime_r(&time, &parts);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &parts);
  return text;
}

}  // namespace deform::service
