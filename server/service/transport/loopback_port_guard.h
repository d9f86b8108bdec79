// One server per port on both loopback families. A client dialling `localhost:P` tries ::1 and
// 127.0.0.1; a server on 127.0.0.1:P does not stop another from binding [::1]:P (another address
// family), which then takes those clients. A server on 127.0.0.1:P therefore also holds [::1]:P,
// and one on [::1]:P holds 127.0.0.1:P: a socket bound there without SO_REUSEADDR and never
// listening (a client's connection to it is refused, so it moves on to the real one), so that
// every later bind of that address and port fails. `localhost:P` binds both families itself.
// Other hosts (a wildcard, a LAN address) are not guarded.
//
// Thread safety: none needed; the guard is created and released by the server's owner.
#pragma once

#include <string>

#include "core/base/status.h"

namespace deform::service {

class LoopbackPortGuard {
 public:
  LoopbackPortGuard() = default;
  // For `listen_address` (HOST:PORT) served on `port`: holds the other loopback family's address
  // on `port`. FAILED_PRECONDITION naming that address when another socket holds it. Nothing held
  // (and OK) for other hosts, or when the host has no such family (no IPv6).
  static StatusOr<LoopbackPortGuard> Hold(const std::string& listen_address, int port);
  // For a loopback `listen_address` asking for port 0: a port free on both families, the other
  // family's address already held by the returned guard (the caller then binds its own family's
  // address on that port). Tries a few kernel-chosen ports; 0 (and no guard) for other hosts or
  // when none was found.
  static int PickFreePort(const std::string& listen_address, LoopbackPortGuard* guard);
  ~LoopbackPortGuard();
  LoopbackPortGuard(LoopbackPortGuard&& other) noexcept;
  LoopbackPortGuard& operator=(LoopbackPortGuard&& other) noexcept;
  LoopbackPortGuard(const LoopbackPortGuard&) = delete;
  LoopbackPortGuard& operator=(const LoopbackPortGuard&) = delete;

  // The address held ("[::1]:P", "127.0.0.1:P"), empty when none.
  const std::string& held() const { return held_; }

 private:
  int fd_ = -1;
  std::string held_;
};

}  // namespace deform::service
