// The server's HTTP side (Boost.Beast): the phone page and its files, the WebSocket on /ws,
// GET /metrics (Prometheus text) and GET /healthz. One io_context on its own threads; each
// connection runs on its own strand and handles one request at a time.
#pragma once

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <thread>
#include <vector>

namespace fluidcast::server {

class HttpServer {
 public:
  struct Routes {
    std::function<std::string()> metrics;  // the body of /metrics
    std::function<bool()> healthy;         // /healthz: 200 when true, else 503
    // Takes over a WebSocket upgrade of /ws.
    std::function<void(boost::beast::tcp_stream,
                       boost::beast::http::request<boost::beast::http::string_body>)>
        websocket;
    // GET paths served from files ("/" is index.html).
    std::map<std::string, std::filesystem::path> files;
  };
  // Listens on address:port (port 0: any free one); throws std::runtime_error naming the address
  // when it cannot.
  HttpServer(const std::string& address, unsigned short port, Routes routes, unsigned threads = 2);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  unsigned short port() const { return port_; }
  void stop();

 private:
  void accept();

  Routes routes_;
  boost::asio::io_context io_;
  boost::asio::ip::tcp::acceptor acceptor_;
  unsigned short port_ = 0;
  std::vector<std::thread> threads_;
};

}  // namespace fluidcast::server
