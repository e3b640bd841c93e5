// A listening TCP socket and its accept loop. When the process has no descriptors left, accepting
// fails at once and would fail again at once: the loop waits (kRetry) and tries again instead of
// spinning, says so once, and reports itself not accepting until descriptors are free again.
#pragma once

#include <atomic>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <functional>
#include <string>

namespace fluidcast::server {

class Listener {
 public:
  static constexpr std::chrono::milliseconds kRetry{100};

  // Listens on address:port (0: any free port), exclusively; throws std::runtime_error naming
  // `what` and the address when it cannot (in use, or not this machine's).
  Listener(boost::asio::io_context& io, const std::string& address, unsigned short port,
           std::string what);
  Listener(const Listener&) = delete;
  Listener& operator=(const Listener&) = delete;

  // Hands each accepted connection to `take` with its client's address (an IPv4 client on a
  // dual-stack port as plain IPv4: the same client either way), on the io_context's threads,
  // while it runs. A connection gone before it is handed over is closed.
  using Take = std::function<void(boost::asio::ip::tcp::socket, boost::asio::ip::address client)>;
  void start(Take take);

  // Stops listening: clients that connect from now on are refused, not left waiting. Only once
  // the io_context no longer runs.
  void close();

  unsigned short port() const { return port_; }
  bool accepting() const { return accepting_.load(); }
  // The listening socket, for an API that is handed its connections (gRPC's) and asks for it.
  int native_handle() { return acceptor_.native_handle(); }

 private:
  void accept();

  std::string what_;
  boost::asio::io_context* io_;
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer retry_;
  Take take_;
  unsigned short port_ = 0;
  std::atomic<bool> accepting_{true};
};

}  // namespace fluidcast::server
