// The gRPC port's accepting, done by deformd rather than by gRPC, so that connections are bounded
// and a server out of descriptors recovers: gRPC's own listener stops accepting for good after
// one EMFILE, and it has no bound on connections per peer address.
//
// Listen() binds every address a "host:port" names (both loopback families for `localhost`; one
// dual-stack socket for a wildcard, as gRPC does) without SO_REUSEPORT, so no second server can
// share the port. Start() runs one thread that accepts each connection and hands its descriptor
// on (to grpc::experimental::ExternalConnectionAcceptor, which owns and closes it), unless
// max_connections are open in all or max_connections_per_address from that peer's address: the
// connection is then closed at once (the client sees its connection end, not a timeout) and the
// refusal reported. Out of descriptors (EMFILE, ENFILE), the acceptor frees its spare descriptor
// to accept and close the oldest waiting connection, pauses its listeners for a moment and tries
// again: it never stops accepting.
//
// A connection counts as open until its socket is shut down (gRPC shuts a connection's socket
// down before closing it) or the peer ends it: the acceptor keeps a duplicate of each descriptor
// it hands on and watches it for the hang-up, which costs a second descriptor per connection (the
// default max_connections allows for it).
//
// Thread safety: Listen, Start and Stop from the owner's thread; port() and open_connections()
// from any thread. The callbacks run on the accepting thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/base/status.h"

namespace deform::service {

struct ConnectionLimits {
  // Open connections in all; 0: from the open-files limit (DefaultMaxConnections).
  int max_connections = 0;
  // Open connections from one peer address (an IPv4 address and its IPv4-mapped IPv6 form are
  // one). Default: 256, the default number of stream slots.
  int max_connections_per_address = 256;
};

// max_connections for a soft limit of `open_files` descriptors: each connection takes two, and
// 256 are left for everything else (mesh files, the store, the HTTP and metrics ports). At least
// 16, at most 16,384.
int DefaultMaxConnections(std::uint64_t open_files);

class ConnectionAcceptor {
 public:
  enum class Refusal {
    kAll,            // max_connections open
    kPerAddress,     // max_connections_per_address open from the peer's address
    kNoDescriptors,  // the process is out of descriptors (the connection was closed unserved)
  };
  // Takes `fd` (a connected, blocking TCP socket) accepted on `listener_fd`.
  using Handoff = std::function<void(int listener_fd, int fd)>;
  // `peer` is the refused peer's address ("" for kNoDescriptors).
  using OnRefused = std::function<void(Refusal reason, const std::string& peer)>;

  // Binds and listens on every address `listen_address` resolves to, all on one port (a port 0:
  // the kernel's pick for the first, the same for the others). FAILED_PRECONDITION "cannot listen
  // on '...'" with the reason when no address can be bound or any one cannot.
  static StatusOr<std::unique_ptr<ConnectionAcceptor>> Listen(const std::string& listen_address,
                                                              ConnectionLimits limits);
  ~ConnectionAcceptor();  // Stop()
  ConnectionAcceptor(const ConnectionAcceptor&) = delete;
  ConnectionAcceptor& operator=(const ConnectionAcceptor&) = delete;

  int port() const { return port_; }
  // The limits in force (max_connections resolved).
  const ConnectionLimits& limits() const { return limits_; }
  // Starts the accepting thread. Once.
  void Start(Handoff handoff, OnRefused on_refused);
  // Closes the listeners and stops the thread; forgets the open connections (their owner closes
  // them). Idempotent.
  void Stop();
  int open_connections() const { return open_.load(std::memory_order_relaxed); }

 private:
  ConnectionAcceptor() = default;
  void Run();
  void AcceptFrom(int listener);
  void Forget(int watched);
  void PauseListeners(bool paused);

  ConnectionLimits limits_;
  int port_ = 0;
  std::vector<int> listeners_;
  int epoll_ = -1;
  int wake_ = -1;   // eventfd: Stop() wakes the thread
  int spare_ = -1;  // kept open to be freed when out of descriptors
  Handoff handoff_;
  OnRefused on_refused_;
  std::thread thread_;
  bool paused_ = false;
  std::atomic<int> open_{0};
  // Accepting-thread-owned: each watched duplicate's peer address, and the count per address.
  std::map<int, std::string> peer_of_;
  std::map<std::string, int> per_address_;
};

}  // namespace deform::service
