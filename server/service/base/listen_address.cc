#include "service/base/listen_address.h"

namespace deform::service {

ListenHostAndPort SplitListenAddress(std::string_view address) {
  const std::size_t colon = address.rfind(':');
  if (colon == std::string_view::npos) return {address, {}, false};
  return {address.substr(0, colon), address.substr(colon + 1), true};
}

int ListenPort(const ListenHostAndPort& split) {
  if (!split.has_port || split.port.empty() || split.port.size() > 5) return -1;
  int port = 0;
  for (const char c : split.port) {
    if (c < '0' || c > '9') return -1;
    port = port * 10 + (c - '0');
  }
  return port <= 65535 ? port : -1;
}

}  // namespace deform::service
