// The bearer token of a WebSocket upgrade or an HTTP call, as the "authorization" value the
// service's Authenticator reads (identity.h): the same tokens as the gRPC port.
//
// Browsers cannot set headers on a WebSocket upgrade, so the page offers its token as a
// subprotocol: `new WebSocket(url, ["deform.v1", "bearer." + base64url(token)])`. The server
// answers with the subprotocol "deform.v1" only (the token is never echoed). Other clients may
// send "Authorization: Bearer TOKEN" instead; the header wins when both are present.
//
// AuthorizationFromUpgrade(authorization_header, subprotocols_header): "Bearer TOKEN" from the
// header if non-empty, else from the first "bearer.<base64url>" entry of the comma-separated
// subprotocol list (padding optional), else empty (no token). A malformed base64url entry gives
// "Bearer " followed by nothing, which the authenticator refuses. Pure; thread-safe.
#pragma once

#include <string>
#include <string_view>

namespace deform::web {

inline constexpr std::string_view kWebSocketSubprotocol = "deform.v1";

std::string AuthorizationFromUpgrade(std::string_view authorization_header,
                                     std::string_view subprotocols_header);

// Whether the comma-separated subprotocol list offers kWebSocketSubprotocol.
bool OffersDeformSubprotocol(std::string_view subprotocols_header);

// base64url (RFC 4648 section 5) without or with padding; nullopt-like empty + false on error.
bool DecodeBase64Url(std::string_view text, std::string* out);

}  // namespace deform::web
