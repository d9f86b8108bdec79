#include "service/transport/loopback_port_guard.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "service/base/listen_address.h"

namespace deform::service {

StatusOr<LoopbackPortGuard> LoopbackPortGuard::Hold(const std::string& listen_address, int port) {
  LoopbackPortGuard guard;
  const std::string_view host = SplitListenAddress(listen_address).host;
  const bool v4 = host == "127.0.0.1";
  if ((!v4 && host != "[::1]") || port <= 0 || port > 65535) return guard;
  const int fd = ::socket(v4 ? AF_INET6 : AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return guard;  // no such family here: nothing to take the clients either
  int rc = 0;
  if (v4) {
    const int only = 1;
    ::setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &only, sizeof only);
    sockaddr_in6 address{};
    address.sin6_family = AF_INET6;
    address.sin6_port = htons(static_cast<unsigned short>(port));
    address.sin6_addr = in6addr_loopback;
    rc = ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  } else {
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<unsigned short>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    rc = ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  }
  const std::string other = (v4 ? "[::1]:" : "127.0.0.1:") + std::to_string(port);
  if (rc != 0) {
    const int error = errno;
    ::close(fd);
    if (error == EADDRNOTAVAIL || error == EAFNOSUPPORT) return guard;
    return Status::FailedPrecondition(
        "cannot listen on '" + listen_address + "': " + other +
        " (the other loopback family's address) is taken: " + std::strerror(error) +
        "; a server there would take the " + "clients that dial localhost:" + std::to_string(port));
  }
  guard.fd_ = fd;
  guard.held_ = other;
  return guard;
}

int LoopbackPortGuard::PickFreePort(const std::string& listen_address, LoopbackPortGuard* guard) {
  const std::string_view host = SplitListenAddress(listen_address).host;
  const bool v4 = host == "127.0.0.1";
  if (!v4 && host != "[::1]") return 0;
  for (int attempt = 0; attempt < 16; ++attempt) {
    // A port the kernel picks in the server's own family ...
    const int fd = ::socket(v4 ? AF_INET : AF_INET6, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return 0;
    int port = 0;
    if (v4) {
      sockaddr_in address{};
      address.sin_family = AF_INET;
      address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      socklen_t length = sizeof address;
      if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0 &&
          ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0) {
        port = ntohs(address.sin_port);
      }
    } else {
      sockaddr_in6 address{};
      address.sin6_family = AF_INET6;
      address.sin6_addr = in6addr_loopback;
      socklen_t length = sizeof address;
      if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0 &&
          ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0) {
        port = ntohs(address.sin6_port);
      }
    }
    // ... that is free in the other family too.
    StatusOr<LoopbackPortGuard> held =
        port > 0 ? Hold(listen_address, port) : StatusOr<LoopbackPortGuard>(Status::Internal(""));
    ::close(fd);  // the server binds it next
    if (held.ok()) {
      *guard = std::move(*held);
      return port;
    }
  }
  return 0;
}

LoopbackPortGuard::~LoopbackPortGuard() {
  if (fd_ >= 0) ::close(fd_);
}

LoopbackPortGuard::LoopbackPortGuard(LoopbackPortGuard&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), held_(std::move(other.held_)) {}

LoopbackPortGuard& LoopbackPortGuard::operator=(LoopbackPortGuard&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    held_ = std::move(other.held_);
  }
  return *this;
}

}  // namespace deform::service
