// A listen address as deformd's flags take it, "host:port" (an IPv6 literal bracketed:
// "[::1]:50051"), split in one place: at its last colon. Every rule about an address (is it
// loopback, which port, which Host names it answers to) starts from this split.
#pragma once

#include <string_view>

namespace deform::service {

struct ListenHostAndPort {
  std::string_view host;  // before the last colon, brackets kept; the whole address without one
  std::string_view port;  // after the last colon; empty without one
  bool has_port = false;  // whether there was a colon
};

// Views into `address`, which must outlive them.
ListenHostAndPort SplitListenAddress(std::string_view address);

// The port of a split address: 0 to 65535 written in 1 to 5 decimal digits; -1 for anything else
// (no colon, no digits, a sign, a space, more than 65535).
int ListenPort(const ListenHostAndPort& split);

}  // namespace deform::service
