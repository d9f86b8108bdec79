// Which Host names the HTTP port answers, so that a web page cannot reach it through DNS
// rebinding: a page on attacker.example whose name the attacker points at 127.0.0.1 sends
// `Host: attacker.example:PORT` and a matching Origin, which an Origin-equals-Host check alone
// accepts. The policy names the hosts the port is for: the loopback names (localhost, 127.0.0.1,
// [::1]), the host of the listen address (unless a wildcard) and the names given with
// --http-allowed-host. A request must carry an allowed Host, and its Origin, when sent, must be
// exactly that host's own origin (http://HOST[:PORT] as the Host header says it).
//
// Names compare case-insensitively; the port in the Host header is not compared (the connection
// arrived on the port). Thread safety: immutable after construction.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace deform::web {

class HttpHostPolicy {
 public:
  // `listen_address` is --http's HOST:PORT; `extra_hosts` the --http-allowed-host names (a bare
  // name or IP literal, an IPv6 literal with or without brackets).
  HttpHostPolicy(std::string_view listen_address, const std::vector<std::string>& extra_hosts);

  // The Host header names an allowed host (with or without a port).
  bool AllowsHost(std::string_view host_header) const;
  // AllowsHost(host_header) and the Origin, when present (`origin` non-null), is that host's
  // own origin.
  bool AllowsRequest(std::string_view host_header, std::optional<std::string_view> origin) const;

  const std::vector<std::string>& names() const { return names_; }

 private:
  std::vector<std::string> names_;  // lower case, IPv6 literals without brackets
};

// The host part of a Host header ("name", "name:port", "[v6]", "[v6]:port") in lower case,
// brackets removed; nullopt when malformed (empty, a bad port, characters a host cannot have).
std::optional<std::string> HostNameOf(std::string_view host_header);

}  // namespace deform::web
