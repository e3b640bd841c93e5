// A raw TCP connection to a port on loopback, for what the tests ask of the server's HTTP side
// byte by byte: connections held open, status lines, whole pages.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <string>

namespace fluidcast::testing {

// A TCP connection to loopback that sends nothing; reads give up after `timeout`: long enough for
// a sanitized server on a loaded machine to answer, shorter where a test waits for nothing to come.
class RawConnection {
 public:
  RawConnection(int port, std::chrono::milliseconds timeout = std::chrono::seconds(10))
      : port_(port) {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    const timeval wait{static_cast<time_t>(timeout.count() / 1000),
                       static_cast<suseconds_t>(timeout.count() % 1000 * 1000)};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof wait);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0;
  }
  ~RawConnection() {
    if (fd_ >= 0) close(fd_);
  }
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;

  bool connected() const { return connected_; }
  // Sends `bytes` as they are (a request or handshake cut short, say); whether they went.
  bool send_bytes(const std::string& bytes) {
    return send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(bytes.size());
  }
  // True when the server closed it (a read sees the end) within the timeout.
  bool closed_by_server() {
    char byte;
    return recv(fd_, &byte, 1, 0) == 0;
  }
  // The status line of GET `path` (with `headers`, each ending in \r\n), or "" when no answer
  // came within the timeout; the connection stays open.
  // `host`: the name the request says it reached the server by (Host); this one's address when
  // empty.
  std::string get(const std::string& path, const std::string& headers = "",
                  const std::string& host = "") {
    const std::string request =
        "GET " + path + " HTTP/1.1\r\nHost: " +
        (host.empty() ? "127.0.0.1:" + std::to_string(port_) : host) + "\r\n" + headers + "\r\n";
    if (send(fd_, request.data(), request.size(), MSG_NOSIGNAL) < 0) return "";
    char reply[256];
    const ssize_t got = recv(fd_, reply, sizeof reply - 1, 0);
    if (got <= 0) return "";
    const std::string text(reply, static_cast<std::size_t>(got));
    return text.substr(0, text.find("\r\n"));
  }
  // The whole answer to GET `path`, read until the server closes the connection (or a read
  // times out); "" when none came.
  std::string page(const std::string& path) {
    const std::string request = "GET " + path +
                                " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port_) +
                                "\r\nConnection: close\r\n\r\n";
    std::string answer;
    if (send(fd_, request.data(), request.size(), MSG_NOSIGNAL) < 0) return answer;
    char chunk[4096];
    for (ssize_t got; (got = recv(fd_, chunk, sizeof chunk, 0)) > 0;) answer.append(chunk, got);
    return answer;
  }

 private:
  int port_;
  int fd_ = -1;
  bool connected_ = false;
};

}  // namespace fluidcast::testing
