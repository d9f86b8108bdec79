// The OpenIGTLink side of the bridge: a TCP listener and its connected receivers.
//
// Each receiver gets the topology first, then the latest published frame whenever a newer one
// exists (latest wins: a slow receiver skips frames, it never holds up the others or the
// stream). Each has its own sending thread and reading thread; a receiver that disconnects or
// sends what cannot be parsed is dropped (logged) and the rest go on. STRING messages a receiver
// sends reach `on_string`; other message types are read and ignored.
//
// Thread safety: Publish and receivers() may be called from any thread; on_string runs on the
// receivers' reading threads, so for two receivers at once (it serializes what it shares).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace deform::igtl_bridge {

// A listening TCP socket on `host` (a numeric IPv4 address) and `port` (0: one the kernel
// picks). -1, with `error` set, when it cannot be bound; `bound_port` receives the port.
int ListenTcp(const std::string& host, int port, int* bound_port, std::string* error);

// True for an address in 127.0.0.0/8.
bool IsLoopbackAddress(const std::string& host);

class ReceiverHub {
 public:
  // `peer`: "HOST:PORT" of the receiver; `text`: the STRING message's content.
  using StringHandler = std::function<void(const std::string& peer, const std::string& text)>;

  // Takes `listen_fd` (ListenTcp). `topology`: the bytes every receiver gets first.
  // `max_receivers`: connections beyond it are closed at once (logged).
  ReceiverHub(int listen_fd, std::string topology, int max_receivers, StringHandler on_string);
  ~ReceiverHub();  // Stop()
  ReceiverHub(const ReceiverHub&) = delete;
  ReceiverHub& operator=(const ReceiverHub&) = delete;

  // Starts accepting.
  void Start();
  // Every receiver sends `frame` (one or more packed messages) next, replacing a frame it has
  // not started sending.
  void Publish(std::shared_ptr<const std::string> frame);
  // Closes the listener and every connection and joins their threads.
  void Stop();
  int receivers();

 private:
  struct Receiver;

  void AcceptLoop();
  void SendLoop(Receiver* receiver);
  void ReadLoop(Receiver* receiver);
  // Joins and removes receivers whose threads have both ended. With `all`, closes every
  // connection first.
  void Reap(bool all);

  const int listen_fd_;
  const std::string topology_;
  const int max_receivers_;
  const StringHandler on_string_;

  std::mutex mu_;
  std::list<std::unique_ptr<Receiver>> receivers_;  // guarded by mu_
  std::shared_ptr<const std::string> latest_;       // guarded by mu_
  std::uint64_t version_ = 0;                       // guarded by mu_
  bool stopping_ = false;                           // guarded by mu_
  std::thread accept_thread_;
};

}  // namespace deform::igtl_bridge
