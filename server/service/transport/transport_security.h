// How deformd's gRPC port is secured: TLS from certificate and key files, optionally mutual TLS
// (clients must present a certificate signed by a given CA), or plaintext.
//
// Policy (TransportPolicy): with a certificate, TLS, always. Without one, plaintext is served on
// a loopback address (127.0.0.0/8, [::1], localhost: only processes on this machine can connect,
// which keeps the demo and the tests working with no setup) and refused on any other address
// unless plaintext was asked for explicitly (TransportSecurity::allow_plaintext, deformd's
// --plaintext), because patient geometry and bearer tokens would cross the network readable.
#pragma once

#include <grpcpp/security/server_credentials.h>

#include <memory>
#include <string>

#include "core/base/status.h"
#include "service/base/service_options.h"
#include "service/transport/server_certificate.h"

namespace deform::service {

// True for "127.x.x.x:port", "[::1]:port", "localhost:port" (what only this machine reaches).
bool IsLoopbackAddress(const std::string& listen_address);

// The credentials for `listen_address` under the policy above: FAILED_PRECONDITION (naming the
// flag to use) for plaintext on a non-loopback address without allow_plaintext, for a key without
// a certificate (or the reverse) or a client CA without a certificate, and for a certificate that
// server_certificate.h refuses (unparsable, not the key's, expired or not yet valid unless
// allow_expired_certificate); NOT_FOUND for an unreadable file. `description` receives what is
// served, for the log ("TLS", "mutual TLS", "plaintext"); `served_certificate`, when given and
// TLS is served, the certificate's names and validity.
StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const TransportSecurity& security, const std::string& listen_address, std::string* description,
    ServerCertificate* served_certificate = nullptr);

}  // namespace deform::service
