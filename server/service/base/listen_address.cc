#include "service/base/listen_address.h"

namespace deform::service {

ListenHostAndPort SplitListenAddress(std::string_view address) {
  const std::size_t colon = address.rfind(':');
  if (colon == std::string_view::npos) return {address, {}, false};
  return {address.substr(0, colon), address.substr(colon + 1), true};
}

}  // namespace deform::service
