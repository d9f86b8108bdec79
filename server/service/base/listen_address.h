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

}  // namespace deform::service
