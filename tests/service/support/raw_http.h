// One HTTP/1.1 exchange over a plain socket, headers exactly as the test writes them (a browser's
// Host and Origin included), for tests of the HTTP port's edges (rpc/web_server.h).
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <string>

namespace deform::test_support {

struct RawHttpResponse {
  int status = 0;    // 0: no status line came back (the connection closed or timed out)
  std::string head;  // the status line and the headers
  std::string body;
};

// Sends `request` (the whole request, head and body) to 127.0.0.1:`port` and reads until the
// server closes the connection or 5 s pass.
inline RawHttpResponse RawHttpExchange(int port, const std::string& request) {
  RawHttpResponse response;
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return response;
  timeval timeout{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<unsigned short>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    ::close(fd);
    return response;
  }
  std::size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = ::send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<std::size_t>(n);
  }
  std::string all;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::recv(fd, buffer, sizeof(buffer), 0);
    if (n <= 0) break;
    all.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  const std::size_t end_of_head = all.find("\r\n\r\n");
  if (all.rfind("HTTP/1.1 ", 0) != 0 || end_of_head == std::string::npos) return response;
  response.status = std::stoi(all.substr(9, 3));
  response.head = all.substr(0, end_of_head);
  response.body = all.substr(end_of_head + 4);
  return response;
}

}  // namespace deform::test_support
