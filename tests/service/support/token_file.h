// Token files for the tests of a server with tokens (access/identity.h): a line per token, and the
// client options that present one.
#pragma once

#include <string>

#include "deform_client.h"
#include "service/access/identity.h"

namespace deform::test_support {

// One token file line: the token's SHA-256, its tenant and its role.
inline std::string TokenLine(const std::string& token, const std::string& tenant,
                             const std::string& role) {
  return service::Sha256Hex(token) + " " + tenant + " " + role + "\n";
}

inline client::ClientOptions WithToken(const std::string& token) {
  client::ClientOptions options;
  options.token = token;
  return options;
}

}  // namespace deform::test_support
