#include "igtl/receiver_hub.h"

#include <arpa/inet.h>
#include <igtlMessageHeader.h>
#include <igtlStringMessage.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>

#include "service/base/log_text.h"

namespace deform::igtl_bridge {
namespace {

using service::EscapeForLog;

// The largest message body a receiver may send: a pose fits in far less. A larger body ends the
// connection (reading it whole would let one receiver make the bridge read without bound).
constexpr std::uint64_t kMaxBodyBytes = 64 * 1024;

// SO_SNDBUF of a receiver's connection (Linux doubles it).
constexpr int kSendBufferBytes = 128 * 1024;

// Reads exactly `size` bytes; false on end of stream or error.
bool ReadAll(int fd, void* data, std::size_t size) {
  auto* bytes = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t got = ::recv(fd, bytes, size, 0);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    bytes += got;
    size -= static_cast<std::size_t>(got);
  }
  return true;
}

bool SendAll(int fd, const std::string& data) {
  const char* bytes = data.data();
  std::size_t size = data.size();
  while (size > 0) {
    const ssize_t sent = ::send(fd, bytes, size, MSG_NOSIGNAL);
    if (sent < 0 && errno == EINTR) continue;
    if (sent <= 0) return false;
    bytes += sent;
    size -= static_cast<std::size_t>(sent);
  }
  return true;
}

std::string PeerName(const sockaddr_in& address) {
  char text[INET_ADDRSTRLEN] = {0};
  inet_ntop(AF_INET, &address.sin_addr, text, sizeof(text));
  return std::string(text) + ":" + std::to_string(ntohs(address.sin_port));
}

}  // namespace

int ListenTcp(const std::string& host, int port, int* bound_port, std::string* error) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  if (port < 0 || port > 65535 || inet_pton(AF_INET, host.c_str(), &address.sin_addr) != 1) {
    *error = "not a numeric IPv4 address and port: " + host + ":" + std::to_string(port);
    return -1;
  }
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    *error = std::string("socket: ") + std::strerror(errno);
    return -1;
  }
  const int one = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0 ||
      ::listen(fd, 16) != 0) {
    *error = "cannot listen on " + host + ":" + std::to_string(port) + ": " + std::strerror(errno);
    ::close(fd);
    return -1;
  }
  socklen_t length = sizeof(address);
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  *bound_port = ntohs(address.sin_port);
  return fd;
}

bool IsLoopbackAddress(const std::string& host) {
  in_addr address{};
  return inet_pton(AF_INET, host.c_str(), &address) == 1 && (ntohl(address.s_addr) >> 24) == 127;
}

struct ReceiverHub::Receiver {
  int fd = -1;
  std::string peer;
  std::condition_variable wake;  // with the hub's mu_
  std::uint64_t sent_version = 0;
  bool closing = false;  // guarded by the hub's mu_
  std::atomic<int> threads_running{2};
  std::thread sender;
  std::thread reader;
};

ReceiverHub::ReceiverHub(int listen_fd, std::string topology, int max_receivers,
                         StringHandler on_string)
    : listen_fd_(listen_fd),
      topology_(std::move(topology)),
      max_receivers_(max_receivers),
      on_string_(std::move(on_string)) {}

ReceiverHub::~ReceiverHub() { Stop(); }

void ReceiverHub::Start() {
  accept_thread_ = std::thread([this] { AcceptLoop(); });
}

void ReceiverHub::Publish(std::shared_ptr<const std::string> frame) {
  std::lock_guard<std::mutex> lock(mu_);
  latest_ = std::move(frame);
  ++version_;
  for (const auto& receiver : receivers_) receiver->wake.notify_one();
}

int ReceiverHub::receivers() {
  std::lock_guard<std::mutex> lock(mu_);
  return static_cast<int>(receivers_.size());
}

void ReceiverHub::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (stopping_) return;
    stopping_ = true;
  }
  if (accept_thread_.joinable()) accept_thread_.join();
  ::close(listen_fd_);
  Reap(/*all=*/true);
}

void ReceiverHub::AcceptLoop() {
  while (true) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (stopping_) return;
    }
    Reap(/*all=*/false);
    pollfd ready{listen_fd_, POLLIN, 0};
    if (::poll(&ready, 1, 200) <= 0) continue;
    sockaddr_in address{};
    socklen_t length = sizeof(address);
    const int fd =
        ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length, SOCK_CLOEXEC);
    if (fd < 0) {
      spdlog::warn("OpenIGTLink: accept failed: {}", std::strerror(errno));
      continue;
    }
    const std::string peer = PeerName(address);
    std::lock_guard<std::mutex> lock(mu_);
    if (static_cast<int>(receivers_.size()) >= max_receivers_) {
      spdlog::warn("OpenIGTLink: receiver {} refused: {} receivers already connected", peer,
                   receivers_.size());
      ::close(fd);
      continue;
    }
    const int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
    // A small send buffer: frames wait in the hub, where a newer one replaces them, rather than
    // queue in the kernel behind a receiver that reads slower than they come.
    const int send_buffer = kSendBufferBytes;
    setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &send_buffer, sizeof(send_buffer));
    auto receiver = std::make_unique<Receiver>();
    receiver->fd = fd;
    receiver->peer = peer;
    Receiver* raw = receiver.get();
    receivers_.push_back(std::move(receiver));
    raw->sender = std::thread([this, raw] { SendLoop(raw); });
    raw->reader = std::thread([this, raw] { ReadLoop(raw); });
    spdlog::info("OpenIGTLink: receiver {} connected ({} connected)", peer, receivers_.size());
  }
}

void ReceiverHub::SendLoop(Receiver* receiver) {
  bool ok = SendAll(receiver->fd, topology_);
  while (ok) {
    std::shared_ptr<const std::string> frame;
    {
      std::unique_lock<std::mutex> lock(mu_);
      receiver->wake.wait(lock, [&] {
        return receiver->closing || (latest_ != nullptr && version_ != receiver->sent_version);
      });
      if (receiver->closing) break;
      frame = latest_;
      receiver->sent_version = version_;
    }
    ok = SendAll(receiver->fd, *frame);
  }
  ::shutdown(receiver->fd, SHUT_RDWR);  // ends the reader too
  {
    std::lock_guard<std::mutex> lock(mu_);
    receiver->closing = true;
  }
  --receiver->threads_running;
}

void ReceiverHub::ReadLoop(Receiver* receiver) {
  igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
  std::string reason = "disconnected";
  while (true) {
    header->InitPack();
    if (!ReadAll(receiver->fd, header->GetPackPointer(),
                 static_cast<std::size_t>(header->GetPackSize()))) {
      break;
    }
    if ((header->Unpack() & igtl::MessageHeader::UNPACK_HEADER) == 0) {
      reason = "sent a header that does not parse";
      break;
    }
    const std::uint64_t body = static_cast<std::uint64_t>(header->GetBodySizeToRead());
    const std::string type = header->GetDeviceType();
    if (body > kMaxBodyBytes) {
      reason = "sent a " + EscapeForLog(type, 12) + " body of " + std::to_string(body) +
               " bytes (at most " + std::to_string(kMaxBodyBytes) + ")";
      break;
    }
    if (type != "STRING") {
      std::string ignored(static_cast<std::size_t>(body), '\0');
      if (!ReadAll(receiver->fd, ignored.data(), ignored.size())) break;
      spdlog::debug("OpenIGTLink: receiver {} sent {} '{}', ignored", receiver->peer,
                    EscapeForLog(type, 12), EscapeForLog(header->GetDeviceName(), 20));
      continue;
    }
    igtl::StringMessage::Pointer message = igtl::StringMessage::New();
    message->SetMessageHeader(header);
    message->AllocatePack();
    if (!ReadAll(receiver->fd, message->GetPackBodyPointer(),
                 static_cast<std::size_t>(message->GetPackBodySize()))) {
      break;
    }
    // The body: encoding (uint16), length (uint16, big-endian), then the text. The length is
    // checked here, before the library trusts it.
    const auto* body_bytes = static_cast<const unsigned char*>(message->GetPackBodyPointer());
    const std::size_t text_bytes =
        body >= 4 ? (static_cast<std::size_t>(body_bytes[2]) << 8 | body_bytes[3]) : 0;
    if (body < 4 || text_bytes > body - 4) {
      spdlog::warn(
          "OpenIGTLink: receiver {}: a STRING message whose length does not fit its "
          "body, ignored",
          receiver->peer);
      continue;
    }
    if ((message->Unpack(/*crccheck=*/1) & igtl::MessageHeader::UNPACK_BODY) == 0) {
      spdlog::warn(
          "OpenIGTLink: receiver {}: a STRING message that does not unpack (bad CRC or "
          "size), ignored",
          receiver->peer);
      continue;
    }
    on_string_(receiver->peer, message->GetString());
  }
  ::shutdown(receiver->fd, SHUT_RDWR);  // ends the sender too, should it be blocked sending
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!stopping_) spdlog::info("OpenIGTLink: receiver {} {}", receiver->peer, reason);
    receiver->closing = true;
    receiver->wake.notify_one();
  }
  --receiver->threads_running;
}

void ReceiverHub::Reap(bool all) {
  std::list<std::unique_ptr<Receiver>> finished;
  {
    std::lock_guard<std::mutex> lock(mu_);
    for (auto it = receivers_.begin(); it != receivers_.end();) {
      Receiver& receiver = **it;
      if (all && !receiver.closing) {
        receiver.closing = true;
        receiver.wake.notify_one();
        ::shutdown(receiver.fd, SHUT_RDWR);
      }
      if (all || receiver.threads_running.load() == 0) {
        finished.push_back(std::move(*it));
        it = receivers_.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (const auto& receiver : finished) {
    receiver->sender.join();
    receiver->reader.join();
    ::close(receiver->fd);
  }
}

}  // namespace deform::igtl_bridge
