#include "service/transport/connection_acceptor.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <set>

#include "service/base/listen_address.h"

namespace deform::service {
namespace {

// How long the listeners rest after the process ran out of descriptors (or buffers).
constexpr int kPauseMs = 100;
// Connections accepted from one listener per wake-up, so that the others and the hang-ups are
// served between them.
constexpr int kAcceptsPerWake = 64;

struct Resolved {
  sockaddr_storage address{};
  socklen_t length = 0;
  bool dual_stack = false;  // an IPv6 wildcard that takes IPv4 too
};

void SetPort(Resolved* resolved, int port) {
  if (resolved->address.ss_family == AF_INET) {
    reinterpret_cast<sockaddr_in*>(&resolved->address)->sin_port =
        htons(static_cast<unsigned short>(port));
  } else {
    reinterpret_cast<sockaddr_in6*>(&resolved->address)->sin6_port =
        htons(static_cast<unsigned short>(port));
  }
}

Resolved Wildcard(int family) {
  Resolved resolved;
  if (family == AF_INET6) {
    auto* address = reinterpret_cast<sockaddr_in6*>(&resolved.address);
    address->sin6_family = AF_INET6;
    address->sin6_addr = in6addr_any;
    resolved.length = sizeof(sockaddr_in6);
    resolved.dual_stack = true;
  } else {
    auto* address = reinterpret_cast<sockaddr_in*>(&resolved.address);
    address->sin_family = AF_INET;
    address->sin_addr.s_addr = htonl(INADDR_ANY);
    resolved.length = sizeof(sockaddr_in);
  }
  return resolved;
}

// The addresses `host` names, without duplicates; a wildcard is IPv6's dual-stack one and then
// IPv4's, of which the first that binds is used (as gRPC does).
StatusOr<std::vector<Resolved>> Resolve(std::string host, bool* wildcard) {
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  *wildcard = host.empty() || host == "0.0.0.0" || host == "::" || host == "*";
  if (*wildcard) return std::vector<Resolved>{Wildcard(AF_INET6), Wildcard(AF_INET)};
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  if (const int rc = ::getaddrinfo(host.c_str(), nullptr, &hints, &found); rc != 0) {
    return Status::FailedPrecondition("cannot resolve '" + host + "': " + ::gai_strerror(rc));
  }
  std::vector<Resolved> out;
  std::set<std::string> seen;
  for (const addrinfo* at = found; at != nullptr; at = at->ai_next) {
    if ((at->ai_family != AF_INET && at->ai_family != AF_INET6) ||
        at->ai_addrlen > sizeof(sockaddr_storage)) {
      continue;
    }
    const std::string key(reinterpret_cast<const char*>(at->ai_addr), at->ai_addrlen);
    if (!seen.insert(key).second) continue;
    Resolved resolved;
    std::memcpy(&resolved.address, at->ai_addr, at->ai_addrlen);
    resolved.length = at->ai_addrlen;
    out.push_back(resolved);
  }
  ::freeaddrinfo(found);
  if (out.empty()) return Status::FailedPrecondition("'" + host + "' names no IP address");
  return out;
}

// A listening socket on `resolved`, or -1 with errno set.
int ListenOn(const Resolved& resolved) {
  const int fd =
      ::socket(resolved.address.ss_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  const int on = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
  if (resolved.address.ss_family == AF_INET6) {
    const int only = resolved.dual_stack ? 0 : 1;
    ::setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &only, sizeof only);
  }
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&resolved.address), resolved.length) != 0 ||
      ::listen(fd, SOMAXCONN) != 0) {
    const int error = errno;
    ::close(fd);
    errno = error;
    return -1;
  }
  return fd;
}

int BoundPort(int fd) {
  sockaddr_storage address{};
  socklen_t length = sizeof address;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) return 0;
  return address.ss_family == AF_INET
             ? ntohs(reinterpret_cast<const sockaddr_in*>(&address)->sin_port)
             : ntohs(reinterpret_cast<const sockaddr_in6*>(&address)->sin6_port);
}

// The peer's address as one key per host: an IPv4-mapped IPv6 address reads as its IPv4 form.
std::string PeerKey(const sockaddr_storage& address) {
  char text[INET6_ADDRSTRLEN] = {};
  if (address.ss_family == AF_INET) {
    ::inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(&address)->sin_addr, text,
                sizeof text);
    return text;
  }
  const in6_addr& v6 = reinterpret_cast<const sockaddr_in6*>(&address)->sin6_addr;
  if (IN6_IS_ADDR_V4MAPPED(&v6)) {
    ::inet_ntop(AF_INET, v6.s6_addr + 12, text, sizeof text);
  } else {
    ::inet_ntop(AF_INET6, &v6, text, sizeof text);
  }
  return text;
}

int OpenSpare() { return ::open("/dev/null", O_RDONLY | O_CLOEXEC); }

}  // namespace

int DefaultMaxConnections(std::uint64_t open_files) {
  const std::uint64_t reserved = 256;
  const std::uint64_t usable = open_files > reserved ? (open_files - reserved) / 2 : 0;
  return static_cast<int>(std::clamp<std::uint64_t>(usable, 16, 16384));
}

StatusOr<std::unique_ptr<ConnectionAcceptor>> ConnectionAcceptor::Listen(
    const std::string& listen_address, ConnectionLimits limits) {
  const auto refuse = [&](const std::string& why) {
    return Status::FailedPrecondition("cannot listen on '" + listen_address + "': " + why);
  };
  const ListenHostAndPort split = SplitListenAddress(listen_address);
  int port = ListenPort(split);
  if (port < 0) return refuse("not HOST:PORT with a port from 0 to 65535");
  if (limits.max_connections == 0) {
    rlimit files{};
    limits.max_connections = DefaultMaxConnections(::getrlimit(RLIMIT_NOFILE, &files) == 0
                                                       ? static_cast<std::uint64_t>(files.rlim_cur)
                                                       : 1024);
  }
  if (limits.max_connections < 0 || limits.max_connections_per_address <= 0) {
    return refuse("the connection limits must be positive");
  }
  bool wildcard = false;
  StatusOr<std::vector<Resolved>> resolved = Resolve(std::string(split.host), &wildcard);
  if (!resolved.ok()) return refuse(resolved.status().message());
  std::unique_ptr<ConnectionAcceptor> acceptor(new ConnectionAcceptor());
  acceptor->limits_ = limits;
  for (Resolved& address : *resolved) {
    if (wildcard && !acceptor->listeners_.empty()) break;  // the dual-stack one took IPv4 too
    SetPort(&address, port);
    const int fd = ListenOn(address);
    if (fd < 0) {
      const int error = errno;
      // A family this machine lacks (no IPv6): the other addresses serve.
      if (error == EAFNOSUPPORT || error == EADDRNOTAVAIL) continue;
      return refuse(std::strerror(error));
    }
    acceptor->listeners_.push_back(fd);
    if (port == 0) port = BoundPort(fd);
  }
  if (acceptor->listeners_.empty() || port == 0) return refuse("no address could be bound");
  acceptor->port_ = port;
  acceptor->epoll_ = ::epoll_create1(EPOLL_CLOEXEC);
  acceptor->wake_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  acceptor->spare_ = OpenSpare();
  if (acceptor->epoll_ < 0 || acceptor->wake_ < 0) return refuse(std::strerror(errno));
  epoll_event event{};
  event.events = EPOLLIN;
  event.data.fd = acceptor->wake_;
  ::epoll_ctl(acceptor->epoll_, EPOLL_CTL_ADD, acceptor->wake_, &event);
  for (const int fd : acceptor->listeners_) {
    event.data.fd = fd;
    if (::epoll_ctl(acceptor->epoll_, EPOLL_CTL_ADD, fd, &event) != 0) {
      return refuse(std::strerror(errno));
    }
  }
  return acceptor;
}

ConnectionAcceptor::~ConnectionAcceptor() {
  Stop();
  for (const int fd : {epoll_, wake_, spare_}) {
    if (fd >= 0) ::close(fd);
  }
}

void ConnectionAcceptor::Start(Handoff handoff, OnRefused on_refused) {
  handoff_ = std::move(handoff);
  on_refused_ = std::move(on_refused);
  thread_ = std::thread([this] { Run(); });
}

void ConnectionAcceptor::Stop() {
  if (thread_.joinable()) {
    const std::uint64_t one = 1;
    (void)!::write(wake_, &one, sizeof one);
    thread_.join();
  }
  for (const int fd : listeners_) ::close(fd);
  listeners_.clear();
  for (const auto& [watched, peer] : peer_of_) ::close(watched);
  peer_of_.clear();
  per_address_.clear();
  open_.store(0, std::memory_order_relaxed);
}

void ConnectionAcceptor::PauseListeners(bool paused) {
  if (paused == paused_) return;
  paused_ = paused;
  for (const int fd : listeners_) {
    epoll_event event{};
    event.events = paused ? 0u : static_cast<std::uint32_t>(EPOLLIN);
    event.data.fd = fd;
    ::epoll_ctl(epoll_, EPOLL_CTL_MOD, fd, &event);
  }
}

void ConnectionAcceptor::Run() {
  std::array<epoll_event, 64> events;
  for (;;) {
    const int ready = ::epoll_wait(epoll_, events.data(), static_cast<int>(events.size()),
                                   paused_ ? kPauseMs : -1);
    if (ready < 0 && errno != EINTR) return;
    if (ready <= 0) {  // the pause is over (or a signal)
      PauseListeners(false);
      continue;
    }
    for (int i = 0; i < ready; ++i) {
      const int fd = events[i].data.fd;
      if (fd == wake_) return;
      if (std::find(listeners_.begin(), listeners_.end(), fd) != listeners_.end()) {
        if (!paused_) AcceptFrom(fd);
      } else {
        Forget(fd);
      }
    }
  }
}

void ConnectionAcceptor::AcceptFrom(int listener) {
  for (int accepted = 0; accepted < kAcceptsPerWake; ++accepted) {
    sockaddr_storage peer{};
    socklen_t length = sizeof peer;
    const int fd = ::accept4(listener, reinterpret_cast<sockaddr*>(&peer), &length,
                             SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      const int error = errno;
      if (error == EAGAIN || error == EWOULDBLOCK) return;
      if (error == EINTR || error == ECONNABORTED || error == EPROTO) continue;
      if (error == EMFILE || error == ENFILE) {
        // The spare descriptor lets the oldest waiting connection be accepted and ended, so its
        // client hears at once instead of waiting out its deadline.
        if (spare_ >= 0) {
          ::close(spare_);
          const int ended = ::accept4(listener, nullptr, nullptr, SOCK_CLOEXEC);
          if (ended >= 0) ::close(ended);
          spare_ = OpenSpare();
        }
        on_refused_(Refusal::kNoDescriptors, "");
      }
      PauseListeners(true);  // out of descriptors or buffers: rest, then accept again
      return;
    }
    const std::string key = PeerKey(peer);
    const auto known = per_address_.find(key);
    const int from_peer = known == per_address_.end() ? 0 : known->second;
    Refusal refusal = Refusal::kAll;
    bool refused = false;
    if (open_connections() >= limits_.max_connections) {
      refused = true;
    } else if (from_peer >= limits_.max_connections_per_address) {
      refused = true;
      refusal = Refusal::kPerAddress;
    }
    int watched = -1;
    if (!refused) {
      watched = ::fcntl(fd, F_DUPFD_CLOEXEC, 0);
      epoll_event event{};
      event.events = 0;  // only the hang-up and errors, which epoll always reports
      event.data.fd = watched;
      if (watched < 0 || ::epoll_ctl(epoll_, EPOLL_CTL_ADD, watched, &event) != 0) {
        if (watched >= 0) ::close(watched);
        refused = true;
        refusal = Refusal::kNoDescriptors;
      }
    }
    if (refused) {
      ::close(fd);
      on_refused_(refusal, refusal == Refusal::kNoDescriptors ? std::string() : key);
      continue;
    }
    const int on = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
    peer_of_[watched] = key;
    ++per_address_[key];
    open_.fetch_add(1, std::memory_order_relaxed);
    handoff_(listener, fd);
  }
}

void ConnectionAcceptor::Forget(int watched) {
  ::epoll_ctl(epoll_, EPOLL_CTL_DEL, watched, nullptr);
  ::close(watched);
  const auto it = peer_of_.find(watched);
  if (it == peer_of_.end()) return;
  const auto count = per_address_.find(it->second);
  if (count != per_address_.end() && --count->second <= 0) per_address_.erase(count);
  peer_of_.erase(it);
  open_.fetch_sub(1, std::memory_order_relaxed);
}

}  // namespace deform::service
