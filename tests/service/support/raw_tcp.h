// Raw TCP connections for the tests of the ports' connection bounds: idle ones (from a chosen
// loopback address) and how soon the server closes one.
#pragma once

#include <arpa/inet.h>
#include <dirent.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <vector>

namespace deform::test_support {

// A TCP connection to 127.0.0.1:port from `from` (a loopback address: all of 127/8 is the
// loopback interface's) that sends nothing; -1 when it cannot connect.
inline int IdleConnection(int port, const char* from = "127.0.0.1") {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in source{};
  source.sin_family = AF_INET;
  ::inet_pton(AF_INET, from, &source.sin_addr);
  if (fd >= 0 && ::bind(fd, reinterpret_cast<sockaddr*>(&source), sizeof(source)) != 0) {
    ::close(fd);
    return -1;
  }
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<unsigned short>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    if (fd >= 0) ::close(fd);
    return -1;
  }
  return fd;
}

// Seconds until the server closes `fd` (reads return 0 or fail), at most about `limit`.
inline double SecondsUntilClosed(int fd, double limit) {
  const auto start = std::chrono::steady_clock::now();
  const auto whole = static_cast<time_t>(limit);
  timeval timeout{whole, static_cast<suseconds_t>((limit - static_cast<double>(whole)) * 1e6)};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  char byte;
  (void)::recv(fd, &byte, 1, 0);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// What the server does with `fd` within `limit` seconds: the bytes it sent before closing it (0:
// closed unserved), or -1 when it is still open then.
inline long BytesBeforeClose(int fd, double limit) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit);
  long bytes = 0;
  char buffer[4096];
  while (std::chrono::steady_clock::now() < deadline) {
    const double left =
        std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
    const auto whole = static_cast<time_t>(left);
    timeval timeout{whole, static_cast<suseconds_t>((left - static_cast<double>(whole)) * 1e6) + 1};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    const ssize_t got = ::recv(fd, buffer, sizeof buffer, 0);
    if (got == 0) return bytes;
    if (got < 0) return errno == EAGAIN || errno == EWOULDBLOCK ? -1 : bytes;
    bytes += got;
  }
  return -1;
}

// The descriptors this process has open.
inline int OpenDescriptors() {
  int count = 0;
  if (DIR* dir = ::opendir("/proc/self/fd")) {
    while (::readdir(dir) != nullptr) ++count;
    ::closedir(dir);
  }
  return count;
}

// While alive, this process is short of descriptors: the soft limit sits `spare` above those
// open at its construction, and the idle connections it opens to 127.0.0.1:port (up to `most`,
// until a socket cannot be made) leave the server's accepts none. Closes them and restores the
// limit when destroyed (or at End()). ok() is false when the limit could not be changed.
class DescriptorShortage {
 public:
  DescriptorShortage(int port, int spare = 24, int most = 64) {
    if (::getrlimit(RLIMIT_NOFILE, &before_) != 0) return;
    rlimit lowered = before_;
    lowered.rlim_cur = static_cast<rlim_t>(OpenDescriptors() + spare);
    if (::setrlimit(RLIMIT_NOFILE, &lowered) != 0) return;
    lowered_ = true;
    for (int i = 0; i < most; ++i) {
      const int fd = IdleConnection(port);
      if (fd < 0) break;
      idle_.push_back(fd);
    }
  }
  ~DescriptorShortage() { End(); }
  DescriptorShortage(const DescriptorShortage&) = delete;
  DescriptorShortage& operator=(const DescriptorShortage&) = delete;

  bool ok() const { return lowered_; }
  std::size_t connections() const { return idle_.size(); }
  // Closes the connections (the limit stays lowered). Idempotent.
  void CloseConnections() {
    for (const int fd : idle_) ::close(fd);
    idle_.clear();
  }
  // Closes the connections and restores the limit now. Idempotent.
  void End() {
    CloseConnections();
    if (lowered_) ::setrlimit(RLIMIT_NOFILE, &before_);
    lowered_ = false;
  }

 private:
  rlimit before_{};
  bool lowered_ = false;
  std::vector<int> idle_;
};

}  // namespace deform::test_support
